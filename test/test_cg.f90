!> The fixed-load constrained-CG solver against the event-exact solver (an independent
!> algorithm for the same complementarity problem) and against Hertz and Segedin.
module test_cg
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: deck_type, read_deck
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use femcod_contact_result, only: contact_result, contact_options
   use femcod_incremental, only: solve_incremental
   use femcod_cg, only: solve_cg, cg_residuals
   use femcod_generate, only: VERIFICATION_DECKS
   use femcod_analytic, only: hertz_approach, segedin_sphere
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_cg

contains

   subroutine collect_cg(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("equals the event-exact solver inside steps on every input/ deck", test_against_incremental), &
         new_unittest("sphere, 0.5 nm mesh: Hertz at 1000 nN, Segedin at 18000 nN", test_sphere), &
         new_unittest("--solver cg without --loads is a usage error", test_usage) &
         ]
   end subroutine collect_cg

   !> At loads strictly inside steps of the event-exact history (midpoints, where the
   !> contact set is unambiguous), the CG solution must have the same contacts and the
   !> same approach; with the stopping rule (gap violations below 1e-8 of the height
   !> range) the approach agrees to about that relative size.
   subroutine test_against_incremental(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_type) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc, cg
      type(cg_residuals), allocatable :: report(:)
      type(status_type) :: status
      integer :: d, k, n, m
      real(dp), allocatable :: loads(:)
      do d = 1, size(VERIFICATION_DECKS)
         if (index(VERIFICATION_DECKS(d), "d05") > 0 .or. index(VERIFICATION_DECKS(d), "d9") > 0) cycle
         call read_deck("input/"//trim(VERIFICATION_DECKS(d))//".deck", deck, status)
         options%loads = [real(dp) ::]
         call solve_incremental(deck, options, inc, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         n = inc%nsteps
         ! Up to five steps spread over the history, at their midpoints.
         m = min(5, n - 1)
         if (m < 1) cycle
         allocate(loads(m))
         do k = 1, m
            associate(s => 1 + (k*(n - 1))/(m + 1))
               loads(k) = (inc%step_load(s) + inc%step_load(s + 1))/2
            end associate
         end do
         options%loads = loads
         call solve_incremental(deck, options, inc, status)
         call solve_cg(deck, options, 1.0e-10_dp, 5000, cg, report, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         do k = 1, m
            call check(error, report(k)%residual < 1.0e-10_dp, trim(VERIFICATION_DECKS(d))//": residual "// &
               to_string(report(k)%residual))
            if (allocated(error)) return
            call check(error, cg%states(k)%contacts, inc%states(k)%contacts, trim(VERIFICATION_DECKS(d))// &
               ": contacts at "//to_string(loads(k))//" nN")
            if (allocated(error)) return
            call check(error, abs(cg%states(k)%approach - inc%states(k)%approach) <= &
               1.0e-8_dp*abs(inc%states(k)%approach), trim(VERIFICATION_DECKS(d))//": approach "// &
               to_string(cg%states(k)%approach)//" vs "//to_string(inc%states(k)%approach))
            if (allocated(error)) return
         end do
         deallocate(loads)
      end do
   end subroutine test_against_incremental

   !> The analytic checks of the legacy suite, with the same tolerances (1 % and 0.5 %).
   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_type) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(cg_residuals), allocatable :: report(:)
      type(status_type) :: status
      real(dp) :: estar, r, segedin, a
      call read_deck("input/sphere_d05.deck", deck, status)
      options%loads = [1000.0_dp, 18000.0_dp]
      call solve_cg(deck, options, 1.0e-8_dp, 5000, res, report, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      estar = 200/(1 - 0.25_dp**2)
      r = 15
      ! Hertz, eq. 4.14.
      call check(error, res%states(1)%approach, hertz_approach(1000.0_dp, r, estar), rel=.true., thr=0.01_dp, &
         message="Hertz at 1000 nN")
      if (allocated(error)) return
      ! Segedin's rigid sphere, the closed form of femcod_analytic (contact radius by bisection).
      call segedin_sphere(18000.0_dp, r, estar, a, segedin)
      call check(error, res%states(2)%approach, segedin, rel=.true., thr=0.005_dp, message="Segedin at 18000 nN")
   end subroutine test_sphere

   subroutine test_usage(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: code
      call run_femcod([string_type("run"), string_type("input/sphere_d1.deck"), string_type("--solver"), &
         string_type("cg"), string_type("--quiet")], code)
      call check(error, code, 2)
   end subroutine test_usage
end module test_cg
