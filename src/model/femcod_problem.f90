!> The contact problem of Appendix B as data: two height maps on a square grid of
!> pixels, the materials of the two bodies and of the contact elements, and the
!> largest number of contacts. What an input deck describes (io/femcod_deck reads and
!> writes it), with no I/O here.
!>
!> Units: nm, GPa. Heights `lower(i, j)` and `upper(i, j)` are row i, column j as in
!> the deck; the upper surface faces the lower one flipped about the horizontal axis
!> (femcod_scene).
module femcod_problem
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_strings, only: int_str
   implicit none
   private
   public :: contact_problem, validate_problem, MAX_NP, MIN_PIXEL, MAX_PIXEL, MAX_HEIGHT, MIN_YOUNG, MAX_YOUNG

   !> Largest NP accepted: NP**2 must fit a default integer.
   integer, parameter :: MAX_NP = 46340
   !> The ranges femcod computes in without overflow (compliances 1/(pi E d), areas
   !> NP^2 d^2, gaps of heights): pixels from 1e-6 nm to 1 mm, heights within 1 km,
   !> moduli from 1e-12 GPa (1 mPa) to 1e300 GPa (a rigid body's stand-in).
   real(dp), parameter :: MIN_PIXEL = 1.0e-6_dp, MAX_PIXEL = 1.0e6_dp, MAX_HEIGHT = 1.0e12_dp
   real(dp), parameter :: MIN_YOUNG = 1.0e-12_dp, MAX_YOUNG = 1.0e300_dp

   !> A contact problem: what a deck (or a pair of height files) describes.
   type :: contact_problem
      !> Free-text label (line 1).
      character(len=:), allocatable :: label
      !> Pixels per side.
      integer :: np = 0
      !> Pixel side d (nm).
      real(dp) :: pixel = 0
      !> Maximum number of contacts.
      integer :: maxcont = 0
      !> Young's moduli (GPa): lower surface, upper surface, contact elements.
      real(dp) :: young(3) = 0
      !> Poisson's ratios: lower surface, upper surface, contact elements.
      real(dp) :: poisson(3) = 0
      !> Heights (nm), `lower(i, j)` is row i, column j as in the deck.
      real(dp), allocatable :: lower(:, :), upper(:, :)
   end type contact_problem

contains

   !> Check the limits of a problem built in memory (the deck reader checks the same, with
   !> the file and line of each value).
   subroutine validate_problem(deck, status)
      type(contact_problem), intent(in) :: deck
      type(status_type), intent(inout) :: status
      integer :: i
      if (deck%np <= 0 .or. deck%np > MAX_NP) then
         call set_error(status, STATUS_BAD_INPUT, "NP must be from 1 to "//int_str(MAX_NP))
      else if (.not. (deck%pixel >= MIN_PIXEL .and. deck%pixel <= MAX_PIXEL)) then
         call set_error(status, STATUS_BAD_INPUT, "PIXEL must be a size from 1e-6 to 1e6 nm")
      else if (deck%maxcont <= 0 .or. deck%maxcont > deck%np**2) then
         call set_error(status, STATUS_BAD_INPUT, "MAXCONT must be from 1 to NP**2")
      else if (index(deck%label, new_line("a")) > 0) then
         call set_error(status, STATUS_BAD_INPUT, "the label must be a single line")
      end if
      if (status%code /= 0) return
      do i = 1, 3
         if (.not. (deck%young(i) >= MIN_YOUNG .and. deck%young(i) <= MAX_YOUNG)) then
            call set_error(status, STATUS_BAD_INPUT, "E"//int_str(i)//" must be a modulus from 1e-12 to 1e300 GPa")
            return
         end if
         if (.not. (deck%poisson(i) > -1 .and. deck%poisson(i) < 0.5_dp)) then
            call set_error(status, STATUS_BAD_INPUT, "NU"//int_str(i)//" must lie in (-1, 0.5)")
            return
         end if
      end do
      if (.not. allocated(deck%lower) .or. .not. allocated(deck%upper)) then
         call set_error(status, STATUS_BAD_INPUT, "the deck has no heights")
      else if (any(shape(deck%lower) /= deck%np) .or. any(shape(deck%upper) /= deck%np)) then
         call set_error(status, STATUS_BAD_INPUT, "the height maps must be NP x NP")
      else if (.not. (all(ieee_is_finite(deck%lower)) .and. all(ieee_is_finite(deck%upper)))) then
         call set_error(status, STATUS_BAD_INPUT, "heights must be finite")
      else if (maxval(abs(deck%lower)) > MAX_HEIGHT .or. maxval(abs(deck%upper)) > MAX_HEIGHT) then
         call set_error(status, STATUS_BAD_INPUT, "heights must lie within 1e12 nm (1 km)")
      end if
   end subroutine validate_problem
end module femcod_problem
