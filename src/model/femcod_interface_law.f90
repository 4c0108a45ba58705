!> The interface between the surfaces: a law for the traction at a gap, and bounds on the
!> pressure. One description that every solver reads:
!> - the law: the hard wall (no traction off contact), or an adhesive potential per area
!>   with work of adhesion W (nN/nm = J/m^2) and range R (nm),
!>       Dugdale:      phi(g) = -W (1 - g/R) for g < R, 0 beyond (a tension W/R within R),
!>       exponential:  phi(g) = -W exp(-g/R)            (a tension (W/R) exp(-g/R));
!> - the bounds: a pixel's force is at least 0 on the hard wall (at least minus the
!>   adhesive tension with a law), and at most fmax = H d^2 (nN) with the plastic cap
!>   (`--plastic`, H the hardness in GPa, d the pixel in nm); fmax = huge: no cap.
!> The event path (solvers/femcod_incremental) caps at the same fmax by its own exact
!> yield events; the fixed-load rounds (femcod_cg's capped_solve) and the gap-variable
!> iteration (femcod_gap_cg) read fmax from here, and move their plastic set by the one
!> rule written here (plastic_round), at most MAX_PLASTIC_ROUNDS times a solve.
!>
!> The law is an enumeration; its name is read once (law_from_name) at the edge.
module femcod_interface_law
   use femcod_kinds, only: dp
   implicit none
   private
   public :: interface_law, LAW_HARD_WALL, LAW_DUGDALE, LAW_EXPONENTIAL, law_from_name, law_name, pixel_tension, &
      make_interface_law, MAX_PLASTIC_ROUNDS

   !> The laws (module header).
   integer, parameter :: LAW_HARD_WALL = 0, LAW_DUGDALE = 1, LAW_EXPONENTIAL = 2
   !> Rounds of the plastic set per solve at most, in either cg path.
   integer, parameter :: MAX_PLASTIC_ROUNDS = 200

   !> A law and its bounds for pixels of area `area` (nm^2).
   type :: interface_law
      integer :: law = LAW_HARD_WALL
      !> Work of adhesion (nN/nm) and range (nm) of an adhesive law.
      real(dp) :: work = 0, range = 1
      !> A pixel's area (nm^2) and the cap on its force (nN; huge: none).
      real(dp) :: area = 1, fmax = huge(1.0_dp)
   contains
      !> True with a cap on the pressure.
      procedure :: capped => law_capped
      !> True with an adhesive law (not the hard wall).
      procedure :: adhesive => law_adhesive
      !> One round of the plastic set.
      procedure :: plastic_round
   end type interface_law

contains

   !> The law named `name` ("none", "dugdale", "exponential"); -1 for any other name.
   pure integer function law_from_name(name) result(law)
      character(len=*), intent(in) :: name
      select case (trim(name))
      case ("none")
         law = LAW_HARD_WALL
      case ("dugdale")
         law = LAW_DUGDALE
      case ("exponential")
         law = LAW_EXPONENTIAL
      case default
         law = -1
      end select
   end function law_from_name

   !> The law's name, as the command line gives it.
   pure function law_name(law) result(name)
      integer, intent(in) :: law
      character(len=:), allocatable :: name
      select case (law)
      case (LAW_DUGDALE)
         name = "dugdale"
      case (LAW_EXPONENTIAL)
         name = "exponential"
      case default
         name = "none"
      end select
   end function law_name

   !> The law `code` (LAW_HARD_WALL, LAW_DUGDALE, LAW_EXPONENTIAL) with work W (J/m^2)
   !> and range R (nm) on pixels of `pixel` nm, capped at the hardness H (GPa) when
   !> `plastic`.
   pure function make_interface_law(code, work, range, pixel, plastic, hardness) result(law)
      integer, intent(in) :: code
      real(dp), intent(in) :: work, range, pixel, hardness
      logical, intent(in) :: plastic
      type(interface_law) :: law
      law%law = code
      law%work = work
      law%range = range
      law%area = pixel**2
      if (plastic) law%fmax = hardness*pixel**2
   end function make_interface_law

   pure logical function law_capped(law)
      class(interface_law), intent(in) :: law
      law_capped = law%fmax < huge(1.0_dp)
   end function law_capped

   pure logical function law_adhesive(law)
      class(interface_law), intent(in) :: law
      law_adhesive = law%law /= LAW_HARD_WALL
   end function law_adhesive

   !> One round of the plastic set under the cap, the rule of both cg paths (the force
   !> variables' capped_solve, the gap variables' rounds): a pixel not capped whose force
   !> (nN) exceeds fmax joins the set, a capped pixel whose gap (nm) exceeds `opened` (nm)
   !> leaves it. `capped` becomes the next round's set; `join` and `leave` say which
   !> pixels moved (the caller asks its grid whether any did, over every rank).
   pure subroutine plastic_round(law, force, gap, opened, capped, join, leave)
      class(interface_law), intent(in) :: law
      real(dp), intent(in) :: force(:, :), gap(:, :), opened
      logical, intent(inout) :: capped(:, :)
      logical, intent(out) :: join(:, :), leave(:, :)
      join = .not. capped .and. force > law%fmax
      leave = capped .and. gap > opened
      capped = (capped .or. join) .and. .not. leave
   end subroutine plastic_round

   !> The adhesive tension d^2 phi'(g) of one pixel (nN, positive: it pulls the surfaces
   !> together), and the curvature d^2 phi''(g) (nN/nm), at gap g >= 0 (nm).
   pure subroutine pixel_tension(law, g, tension, curvature)
      type(interface_law), intent(in) :: law
      real(dp), intent(in) :: g
      real(dp), intent(out) :: tension, curvature
      tension = 0
      curvature = 0
      select case (law%law)
      case (LAW_DUGDALE)
         if (g < law%range) tension = law%area*law%work/law%range
      case (LAW_EXPONENTIAL)
         tension = law%area*(law%work/law%range)*exp(-g/law%range)
         curvature = -tension/law%range
      end select
   end subroutine pixel_tension
end module femcod_interface_law
