!> The contact scene of Appendix B: the upper surface flipped about the horizontal
!> axis (Fig. B.1: upper row i faces lower row NP+1-i) and the initial gaps with the
!> two surfaces touching at the highest pair of voxels.
module femcod_scene
   use femcod_kinds, only: dp
   implicit none
   private
   public :: flip_upper, initial_gaps, initial_gap_map

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
end module femcod_scene
