!> The contact scene of Appendix B: the upper surface flipped about the horizontal
!> axis (Fig. B.1: upper row i faces lower row NP+1-i) and the initial gaps with the
!> two surfaces touching at the highest pair of voxels.
module femcod_scene
   use femcod_kinds, only: dp
   implicit none
   private
   public :: flip_upper, initial_gaps

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

   !> Initial gaps (nm), pixel numbered row-wise: k = (i-1)*NP + j.
   !>   g(i,j) = max_{k,l}[hl(k,l) + hu(NP+1-k,l)] - [hl(i,j) + hu(NP+1-i,j)]
   !> Each surface is first taken relative to its own highest point: heights offset by
   !> a large constant then subtract exactly (Sterbenz), and only the small relative
   !> heights are added, so no offset cancels in the sum.
   pure function initial_gaps(lower, upper) result(gaps)
      real(dp), intent(in) :: lower(:, :), upper(:, :)
      real(dp) :: gaps(size(lower))
      real(dp) :: total(size(lower, 1), size(lower, 2))
      total = (lower - maxval(lower)) + flip_upper(upper - maxval(upper))
      ! Row-wise numbering: transpose so that j runs fastest.
      gaps = reshape(transpose(maxval(total) - total), [size(lower)])
   end function initial_gaps
end module femcod_scene
