!> Degenerate inputs are hard cases too (issue 47, section 2): a flat surface, one peak
!> pixel, two equal peaks, heights spanning 1e-300, 1e-12 and 1e6 nm, a tilted plane,
!> loads of 1e-300 and 1e300 nN, moduli of 1e-6 and 1e6 GPa, for every solver. Each row
!> is the solver's answer against a reference from analysis or from the dense solve of
!> test/oracles with the contact set the analysis gives (the whole grid for a flat, the
!> peaks alone below the next touch), or the solver's refusal (its exit code and
!> message). The stability suite asserts the bounds; --stability-report prints the
!> table. No I/O here.
module degenerate_cases
   use, intrinsic :: iso_fortran_env, only: real128
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: verification_spec, scene_spec, build_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, solver_from_name, BOUNDARY_PERIODIC
   use femcod_solver, only: solve_contact
   use stability_cases, only: legacy_condition
   use oracles, only: love_table, exact_state, composite_compliance, love_quad
   implicit none
   private
   public :: degenerate_row, degenerate_family, DEGENERATE_SOLVERS

   !> The solvers of the family: the three on the free surface, cg on the periodic cell.
   character(len=*), parameter :: DEGENERATE_SOLVERS(4) = [character(len=12) :: "incremental", "legacy", "cg", &
      "cg periodic"]

   !> One case and one solver: the relative error of the approach against the
   !> reference, and its bound; or the refusal (code > 0, message).
   type :: degenerate_row
      character(len=:), allocatable :: scene, solver, reference, message
      real(dp) :: error = 0, bound = 0
      integer :: code = 0
   end type degenerate_row

   integer, parameter :: NP = 8

contains

   !> Every case for every solver that applies (the periodic cell only for the flat
   !> scenes, where its closed form is the uniform pressure).
   subroutine degenerate_family(rows)
      type(degenerate_row), allocatable, intent(out) :: rows(:)
      type(contact_problem) :: deck
      integer :: s
      allocate(rows(0))
      do s = 1, 3
         call flat_case("flat", 0.0_dp, 100.0_dp, s)
         call flat_case("heights within 1e-300 nm", 1.0e-300_dp, 100.0_dp, s)
         call flat_case("heights within 1e-12 nm", 1.0e-12_dp, 100.0_dp, s)
         call flat_case("flat, load 1e-300 nN", 0.0_dp, 1.0e-300_dp, s)
         call flat_case("flat, load 1e300 nN", 0.0_dp, 1.0e300_dp, s)
         call peaks_case("one peak pixel (1 nm)", 1.0_dp, [NP/2], [NP/2], s)
         call peaks_case("one peak pixel (1e6 nm)", 1.0e6_dp, [NP/2], [NP/2], s)
         call peaks_case("two equal peaks", 1.0_dp, [2, 6], [NP/2, NP/2], s)
         call peaks_case("tilted plane (0.1 nm a pixel)", -1.0_dp, [NP], [NP], s)
         call modulus_case(1.0e-6_dp, s)
         call modulus_case(1.0e6_dp, s)
      end do
      call periodic_flat("flat", 0.0_dp, 100.0_dp)
      call periodic_flat("heights within 1e-12 nm", 1.0e-12_dp, 100.0_dp)
      call periodic_flat("flat, load 1e300 nN", 0.0_dp, 1.0e300_dp)
   contains
      !> The flat scene (plus `ripple` times a fixed pattern in [0, 1]) at `load`: the
      !> whole grid in contact, the rigid square punch, by the dense solve.
      subroutine flat_case(name, ripple, load, s)
         character(len=*), intent(in) :: name
         real(dp), intent(in) :: ripple, load
         integer, intent(in) :: s
         type(degenerate_row) :: row
         real(dp) :: reference
         call scene(ripple, deck)
         reference = dense_approach(deck, load, all_pixels_i(), all_pixels_j())
         call run_row(name, s, deck, load, reference, "dense solve, the whole grid in contact", row)
         rows = [rows, row]
      end subroutine flat_case

      !> Peaks `height` nm above a flat at (pi, pj) (height < 0: the tilted plane 0.1 (i
      !> + j) nm, whose top is the last pixel) at 1 nN: the peaks alone carry it (their
      !> approach, about 5e-3 nm a nN, stays far below the next pixel's gap).
      subroutine peaks_case(name, height, pi, pj, s)
         character(len=*), intent(in) :: name
         real(dp), intent(in) :: height
         integer, intent(in) :: pi(:), pj(:)
         integer, intent(in) :: s
         type(degenerate_row) :: row
         integer :: i, j, k
         call scene(0.0_dp, deck)
         if (height < 0) then
            do j = 1, NP
               do i = 1, NP
                  deck%lower(i, j) = 0.1_dp*(i + j)
               end do
            end do
         else
            do k = 1, size(pi)
               deck%lower(pi(k), pj(k)) = height
            end do
         end if
         call run_row(name, s, deck, 1.0_dp, dense_approach(deck, 1.0_dp, pi, pj), &
            "dense solve, the peaks alone in contact", row)
         rows = [rows, row]
      end subroutine peaks_case

      !> The sphere of input/sphere_d2.deck with every modulus times `factor` at 1000 nN
      !> times `factor`: the contact problem is homogeneous in P/E, so the approach is the
      !> nominal one's (the same solver's at 200 GPa and 1000 nN), to round-off.
      subroutine modulus_case(factor, s)
         real(dp), intent(in) :: factor
         integer, intent(in) :: s
         type(degenerate_row) :: row
         type(scene_spec) :: spec
         type(status_type) :: status
         real(dp) :: nominal
         call verification_spec("sphere_d2", spec, status)
         call build_problem(spec, deck, status)
         nominal = solved_approach(deck, s, 1000.0_dp, row)
         if (row%code == 0) then
            deck%young = deck%young*factor
            call run_row("sphere, E x "//sci(factor)//", load x "//sci(factor), s, deck, 1000*factor, nominal, &
               "the same solver at E x 1 (P/E invariance)", row)
         end if
         rows = [rows, row]
      end subroutine modulus_case

      !> The periodic flat cell: uniform pressure P/(NP d)^2 (every pixel alike by
      !> translation), the relative error of the largest pressure.
      subroutine periodic_flat(name, ripple, load)
         character(len=*), intent(in) :: name
         real(dp), intent(in) :: ripple, load
         type(degenerate_row) :: row
         type(contact_options) :: options
         type(contact_result) :: res
         type(status_type) :: status
         call scene(ripple, deck)
         row%scene = name
         row%solver = "cg periodic"
         row%reference = "uniform pressure P/(NP d)^2 (closed form; with ripples r, to 10 r/(c I(0,0) P/NP^2))"
         options%solver = solver_from_name("cg")
         options%boundary = BOUNDARY_PERIODIC
         options%loads = [load]
         options%cg%tol = 1.0e-10_dp
         call solve_contact(deck, options, res, status)
         ! Ripples of height r move the pressures by about r over a pixel's own
         ! displacement under the mean force, c I(0,0) P/NP^2: ten times that, or 1e-9.
         row%bound = max(1.0e-9_dp, 10*ripple/(composite_compliance(deck)* &
            real(love_quad(0.0_real128, 0.0_real128), dp)*load/NP**2))
         if (status%code /= 0) then
            row%code = status%code
            row%message = status%message
         else
            row%error = abs(res%states(1)%max_pressure/(load/(NP*deck%pixel)**2) - 1)
         end if
         rows = [rows, row]
      end subroutine periodic_flat
   end subroutine degenerate_family

   !> Solve `deck` at `load` with solver number s and measure the approach against
   !> `reference` (relative); the bound by solver: the event-exact incremental path
   !> 1e-10, cg at --tol 1e-10 1e-7, legacy 10 eps times the exact condition of its
   !> systems (TRFACT cancels digits, doc/stability.md), at least 1e-10.
   subroutine run_row(name, s, deck, load, reference, source, row)
      character(len=*), intent(in) :: name, source
      integer, intent(in) :: s
      type(contact_problem), intent(inout) :: deck
      real(dp), intent(in) :: load, reference
      type(degenerate_row), intent(out) :: row
      real(dp) :: approach
      approach = solved_approach(deck, s, load, row)
      row%scene = name
      row%reference = source
      if (row%code == 0) row%error = abs(approach/reference - 1)
   end subroutine run_row

   !> The approach (nm) solver number s gives for `deck` at `load`, at --tol 1e-10 for
   !> cg; the row's solver, bound, and its refusal (code, message) where there is one
   !> (code -1: the state was not reached, a warning of the run).
   real(dp) function solved_approach(deck, s, load, row) result(approach)
      type(contact_problem), intent(inout) :: deck
      integer, intent(in) :: s
      real(dp), intent(in) :: load
      type(degenerate_row), intent(inout) :: row
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      approach = 0
      row%solver = trim(DEGENERATE_SOLVERS(s))
      row%code = 0
      options%solver = solver_from_name(row%solver)
      options%loads = [load]
      options%cg%tol = 1.0e-10_dp
      call solve_contact(deck, options, res, status)
      if (status%code /= 0) then
         row%code = status%code
         row%message = status%message
         return
      end if
      if (.not. res%states(1)%reached) then
         row%code = -1
         row%message = "not reached (a warning of the run)"
         return
      end if
      approach = res%states(1)%approach
      select case (row%solver)
      case ("incremental")
         row%bound = 1.0e-10_dp
      case ("cg")
         row%bound = 1.0e-7_dp
      case default
         row%bound = max(1.0e-10_dp, 10*epsilon(1.0_dp)*legacy_condition(deck, res))
      end select
   end function solved_approach

   !> The NP x NP scene on a rigid flat: the lower surface flat plus `ripple` times a
   !> fixed pattern in [0, 1], E = 200 GPa, nu = 0.25, d = 1 nm, MAXCONT NP^2.
   subroutine scene(ripple, deck)
      real(dp), intent(in) :: ripple
      type(contact_problem), intent(out) :: deck
      integer :: i, j
      deck%label = "degenerate"
      deck%np = NP
      deck%pixel = 1
      deck%maxcont = NP*NP
      deck%young = [200.0_dp, 2.0e12_dp, 2.0e12_dp]
      deck%poisson = 0.25_dp
      allocate(deck%lower(NP, NP), deck%upper(NP, NP))
      deck%upper = 0
      do j = 1, NP
         do i = 1, NP
            deck%lower(i, j) = ripple*mod(7*i + 3*j, 5)/4.0_dp
         end do
      end do
   end subroutine scene

   !> The approach of the dense solve with the contacts (ci, cj) at `load`.
   real(dp) function dense_approach(deck, load, ci, cj) result(approach)
      type(contact_problem), intent(in) :: deck
      real(dp), intent(in) :: load
      integer, intent(in) :: ci(:), cj(:)
      real(dp), allocatable :: forces(:)
      integer :: info
      allocate(forces(size(ci)))
      call exact_state(deck, love_table(deck%np), ci, cj, load, forces, approach, info)
   end function dense_approach

   pure function all_pixels_i() result(ci)
      integer :: ci(NP*NP), k
      ci = [((k - 1)/NP + 1, k = 1, NP*NP)]
   end function all_pixels_i

   pure function all_pixels_j() result(cj)
      integer :: cj(NP*NP), k
      cj = [(mod(k - 1, NP) + 1, k = 1, NP*NP)]
   end function all_pixels_j

   function sci(x) result(text)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=16) :: buf
      write(buf, '(es8.1)') x
      text = trim(adjustl(buf))
   end function sci
end module degenerate_cases
