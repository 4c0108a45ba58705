!> The contact scene of Appendix B: the upper surface flipped about the horizontal
!> axis (Fig. B.1: upper row i faces lower row NP+1-i) and the initial gaps with the
!> two surfaces touching at the highest pair of voxels.
module femcod_scene
   use femcod_kinds, only: dp
   implicit none
   private
   public :: flip_upper, initial_gaps, initial_gap_map, slope_sums, rms_slope

contains

   !> The upper heights as seen from the lower surface: row i of the result is row
   !> NP+1-i of the deck's upper surface.
   pure function flip_upper(upper) result(facing)
      real(dp), intent(in) :: upper(:, :)
      real(dp) :: facing(size(upper, 1), size(upper, 2))
      integer :: n
      n = size(upper, 1)
      facing = upper(n:1:-1, :)
   end function flip_upper

   !> Initial gaps (nm), pixel numbered row-wise: k = (i-1)*NP + j (initial_gap_map's
   !> values, for the solvers that number pixels so).
   function initial_gaps(lower, upper) result(gaps)
      real(dp), intent(in) :: lower(:, :), upper(:, :)
      real(dp) :: gaps(size(lower))
      ! Row-wise numbering: transpose so that j runs fastest.
      gaps = reshape(transpose(initial_gap_map(lower, upper)), [size(lower)])
   end function initial_gaps

   !> Initial gaps (nm) as a map, gaps(i, j) at pixel (i, j):
   !>   g(i,j) = max_{k,l}[hl(k,l) + hu(NP+1-k,l)] - [hl(i,j) + hu(NP+1-i,j)]
   !> Each surface is first taken relative to its own highest point: heights offset by
   !> a large constant then subtract exactly (Sterbenz), and only the small relative
   !> heights are added, so no offset cancels in the sum. Two passes on all threads,
   !> no temporary map (at NP = 4096 the whole-array form with its transposes took 1 s).
   function initial_gap_map(lower, upper) result(gaps)
      real(dp), intent(in) :: lower(:, :), upper(:, :)
      real(dp), allocatable :: gaps(:, :)
      real(dp) :: top_lower, top_upper, top
      integer :: n, i, j
      n = size(lower, 1)
      top_lower = maxval(lower)
      top_upper = maxval(upper)
      allocate(gaps(n, size(lower, 2)))
      top = -huge(1.0_dp)
      !$omp parallel do private(i) reduction(max:top)
      do j = 1, size(lower, 2)
         do i = 1, n
            gaps(i, j) = (lower(i, j) - top_lower) + (upper(n + 1 - i, j) - top_upper)
            top = max(top, gaps(i, j))
         end do
      end do
      !$omp parallel do private(i)
      do j = 1, size(lower, 2)
         do i = 1, n
            gaps(i, j) = top - gaps(i, j)
         end do
      end do
   end function initial_gap_map

   !> The sums of a map's squared forward differences along its columns (down the rows,
   !> i) and along its rows (j), and the numbers of pixel pairs in each, over the columns
   !> 1 .. size(g, 2) - 1 of `g` (the last column only down its rows): a slab's share of
   !> rms_slope. `wrap` also pairs the last row with the first (a periodic cell).
   pure subroutine slope_sums(g, wrap, sums, pairs)
      real(dp), intent(in) :: g(:, :)
      logical, intent(in) :: wrap
      real(dp), intent(out) :: sums(2), pairs(2)
      integer :: n, i, j
      n = size(g, 1)
      sums = 0
      do j = 1, size(g, 2)
         do i = 1, n - 1
            sums(1) = sums(1) + (g(i + 1, j) - g(i, j))**2
         end do
         if (wrap) sums(1) = sums(1) + (g(1, j) - g(n, j))**2
      end do
      do j = 1, size(g, 2) - 1
         do i = 1, n
            sums(2) = sums(2) + (g(i, j + 1) - g(i, j))**2
         end do
      end do
      pairs = [real(size(g, 2), dp)*merge(n, n - 1, wrap), real(max(size(g, 2) - 1, 0), dp)*n]
   end subroutine slope_sums

   !> The rms slope h'_rms (1) of a map g (nm) of pixel d (nm): sqrt(<(dg/dx)^2> +
   !> <(dg/dy)^2>), each mean over the grid's pairs of neighbouring pixels by forward
   !> differences, (g(i+1, j) - g(i, j))/d (NP (NP - 1) pairs a direction on the free
   !> surface; NP^2, wrapping, on a periodic cell). Of the initial gaps: the composite
   !> surface's slope at the pixel, the slope kappa's load scale takes.
   pure real(dp) function rms_slope(g, pixel, periodic)
      real(dp), intent(in) :: g(:, :), pixel
      logical, intent(in) :: periodic
      real(dp) :: sums(2), pairs(2)
      integer :: n
      n = size(g, 1)
      call slope_sums(g, periodic, sums, pairs)
      if (periodic) then
         sums(2) = sums(2) + sum((g(:, 1) - g(:, size(g, 2)))**2)
         pairs(2) = pairs(2) + n
      end if
      rms_slope = sqrt(sums(1)/max(pairs(1), 1.0_dp) + sums(2)/max(pairs(2), 1.0_dp))/pixel
   end function rms_slope
end module femcod_scene
