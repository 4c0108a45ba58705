!> Numerical stability on hard cases (doc/stability.md): the bounds asserted here come
!> from analysis (quoted with each test); the measured values are tabulated by
!> `femcod stability`.
module test_stability
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use femcod_contact_result, only: contact_result, STOP_MAXCONT
   use femcod_generate, only: scene_spec, build_problem, verification_spec
   use stability_cases, only: stiffness_row, stiffness_sweep, symmetry_defect, symmetric_scene, flat_on_flat, &
      single_pixel, first_spike_event, identical_surfaces, height_offset, length_scaling, poisson_limit, &
      love_precision, solve_precision, long_run_drift, solve, STIFFNESS_RATIOS
   use degenerate_cases, only: degenerate_row, degenerate_family
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_stability

   real(dp), parameter :: eps = epsilon(1.0_dp)

contains

   subroutine collect_stability(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("stiff springs: 1/ratio model error, round-off within eps x condition", test_stiffness), &
         new_unittest("symmetry: sphere on a centre and a corner, square punch, sinusoid", test_symmetry), &
         new_unittest("flat on flat: all pixels at once, equal to a dense solve", test_flat), &
         new_unittest("degenerate inputs: every solver answers to its bound or refuses", test_degenerate), &
         new_unittest("NP = 1, nu = 0.25 and nu = 0: closed form", test_single_pixel), &
         new_unittest("requested loads of zero, negative and beyond MAXCONT", test_loads), &
         new_unittest("a spike 1000 times the rms: first event in closed form", test_spike), &
         new_unittest("identical surfaces equal their sum on a flat", test_identical), &
         new_unittest("1e6 nm offsets with 1e-3 nm roughness: input rounding only", test_offset), &
         new_unittest("pixels of 1e-3 and 1e4 nm: exact scaling", test_scaling), &
         new_unittest("contact elements at nu = 0.5 - 1e-9: the default solver is immune", test_poisson), &
         new_unittest("Love coefficients and a solve against quadruple precision", test_precision), &
         new_unittest("a 2000-event run: no drift against a fresh solve", test_drift) &
         ]
   end subroutine collect_stability

   !> Analysis (femcod_stability%stiffness_sweep): 0 <= delta(s) - delta(0) <= s |f|^2, so
   !> the incremental error is positive and proportional to 1/ratio; a backward-stable
   !> solve errs by at most about eps times the condition number.
   subroutine test_stiffness(error)
      type(error_type), allocatable, intent(out) :: error
      type(stiffness_row) :: rows(size(STIFFNESS_RATIOS))
      type(status_type) :: st
      real(dp) :: slope
      integer :: k
      call stiffness_sweep(rows, st)
      call check(error, st%code, 0, st%message)
      if (allocated(error)) return
      slope = rows(2)%incremental*rows(2)%ratio
      do k = 1, size(rows)
         call check(error, rows(k)%incremental > 0, "compliant springs add approach (ratio "//to_string(rows(k)%ratio)//")")
         if (allocated(error)) return
         if (rows(k)%ratio <= 1.0e8_dp) then
            call check(error, abs(rows(k)%incremental*rows(k)%ratio/slope - 1) < 0.05_dp, &
               "model error linear in 1/ratio at "//to_string(rows(k)%ratio))
            if (allocated(error)) return
         end if
         call check(error, rows(k)%legacy_roundoff <= eps*rows(k)%condition, "legacy round-off "// &
            to_string(rows(k)%legacy_roundoff)//" within eps x condition "//to_string(eps*rows(k)%condition))
         if (allocated(error)) return
      end do
      call check(error, rows(size(rows))%incremental < 1.0e-11_dp, "incremental at 1e12: "// &
         to_string(rows(size(rows))%incremental))
      if (allocated(error)) return
      ! mkdeck's default ratio, 1e10, keeps the default solver's error below 1e-8.
      call check(error, rows(5)%ratio == 1.0e10_dp .and. rows(5)%incremental < 1.0e-8_dp, "default ratio error")
   end subroutine test_stiffness

   !> Scenes invariant under the eight symmetries of the square: every state's contact
   !> set symmetric, forces to round-off (the incremental solver); the legacy solver
   !> on the small ones, within its larger round-off.
   subroutine test_symmetry(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: scenes(4) = [character(len=13) :: "sphere-centre", "sphere-corner", &
         "square-punch", "sinusoid"]
      type(contact_problem) :: deck
      type(status_type) :: st
      real(dp) :: defect
      integer :: k, sets, nstates
      do k = 1, size(scenes)
         call symmetric_scene(trim(scenes(k)), deck, st)
         call symmetry_defect(deck, "incremental", defect, sets, nstates, st)
         call check(error, st%code, 0, st%message)
         if (allocated(error)) return
         call check(error, nstates > 0 .and. sets == 0, trim(scenes(k))//": "//to_string(sets)// &
            " asymmetric contact sets in "//to_string(nstates)//" states")
         if (allocated(error)) return
         call check(error, defect < 1.0e-12_dp, trim(scenes(k))//": force asymmetry "//to_string(defect))
         if (allocated(error)) return
         if (deck%np > 16) cycle
         call symmetry_defect(deck, "legacy", defect, sets, nstates, st)
         call check(error, st%code == 0 .and. sets == 0 .and. defect < 1.0e-8_dp, trim(scenes(k))// &
            ", legacy: asymmetric sets "//to_string(sets)//", force asymmetry "//to_string(defect))
         if (allocated(error)) return
      end do
   end subroutine test_symmetry

   subroutine test_flat(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: d, condition
      integer :: first
      call flat_on_flat("incremental", first, d, condition, st)
      call check(error, st%code, 0, st%message)
      if (allocated(error)) return
      call check(error, first, 64, "incremental: contacts of the first step")
      if (allocated(error)) return
      call check(error, d < 1.0e-12_dp, "incremental vs dense solve: "//to_string(d))
      if (allocated(error)) return
      call flat_on_flat("legacy", first, d, condition, st)
      call check(error, st%code == 0 .and. first == 64, "legacy: contacts of the first step")
      if (allocated(error)) return
      call check(error, d <= eps*condition, "legacy vs dense solve "//to_string(d)//" within eps x condition")
   end subroutine test_flat

   !> Issue 47's degenerate family (test/degenerate_cases): each row is an answer within
   !> its bound of the reference from analysis or the dense solve, or a refusal with an
   !> exit code and a message. Before the fix cg failed the flat scenes (exit 4 after
   !> 2000 iterations, "residual 2.9e+299": the residual was measured against a height
   !> range of 0).
   subroutine test_degenerate(error)
      type(error_type), allocatable, intent(out) :: error
      type(degenerate_row), allocatable :: rows(:)
      integer :: k
      call degenerate_family(rows)
      call check(error, size(rows) >= 30, "the family has "//to_string(size(rows))//" rows")
      if (allocated(error)) return
      do k = 1, size(rows)
         associate(r => rows(k))
            if (r%code /= 0) then
               call check(error, r%code >= 2 .and. r%code <= 4 .and. len_trim(r%message) > 0, r%scene//", "// &
                  r%solver//": neither an answer nor a refusal with its reason (code "//to_string(r%code)//")")
            else
               call check(error, r%error <= r%bound, r%scene//", "//r%solver//": relative error "// &
                  to_string(r%error)//" above "//to_string(r%bound))
            end if
            if (allocated(error)) return
         end associate
      end do
   end subroutine test_degenerate

   !> One pixel: approach = P (c I(0,0) + 3/k) (femcod_stability%single_pixel).
   subroutine test_single_pixel(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: d
      call single_pixel("incremental", 0.25_dp, d, st)
      call check(error, st%code == 0 .and. d < 4*eps, "incremental, nu = 0.25: "//to_string(d))
      if (allocated(error)) return
      call single_pixel("incremental", 0.0_dp, d, st)
      call check(error, st%code == 0 .and. d < 4*eps, "incremental, nu = 0: "//to_string(d))
      if (allocated(error)) return
      call single_pixel("legacy", 0.0_dp, d, st)
      call check(error, st%code == 0 .and. d < 1.0e-9_dp, "legacy, nu = 0: "//to_string(d))
   end subroutine test_single_pixel

   !> Load 0 is the state at the first contact (approach exactly 0); a negative load is a
   !> usage error; a load beyond MAXCONT is not reached and the run says why.
   subroutine test_loads(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_result) :: res
      type(status_type) :: st
      integer :: code
      call verification_spec("sphere_d2", spec, st)
      call build_problem(spec, deck, st)
      call solve(deck, "incremental", [0.0_dp, 1.0e12_dp], res, st)
      call check(error, st%code, 0, st%message)
      if (allocated(error)) return
      call check(error, res%states(1)%reached .and. res%states(1)%approach == 0 .and. res%states(1)%contacts == 1, &
         "the state at zero load")
      if (allocated(error)) return
      call check(error, .not. res%states(2)%reached .and. res%stop_reason == STOP_MAXCONT, &
         "a load beyond MAXCONT is not reached")
      if (allocated(error)) return
      call run_femcod([string_type("run"), string_type("input/sphere_d2.deck"), string_type("--loads"), &
         string_type("-5"), string_type("--quiet")], code)
      call check(error, code, 2, "a negative load is a usage error")
   end subroutine test_loads

   subroutine test_spike(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: d
      integer :: missed
      call first_spike_event("incremental", d, missed, st)
      call check(error, st%code == 0 .and. d < 1.0e-12_dp .and. missed == 0, "first event vs min g/(self - c I): "// &
         to_string(d)//", missed "//to_string(missed))
   end subroutine test_spike

   !> The composite rule: the gap depends on hl + flip(hu) only, the compliance on c1 + c2.
   subroutine test_identical(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: d
      call identical_surfaces(d, st)
      call check(error, st%code == 0 .and. d < 1.0e-12_dp, "history difference "//to_string(d))
   end subroutine test_identical

   !> The bound is the input's own rounding: four heights per gap, half an ulp of 1e6 each,
   !> over the smallest gap that closes.
   subroutine test_offset(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: d, bound
      call height_offset(d, bound, st)
      call check(error, st%code == 0 .and. d <= bound, "difference "//to_string(d)//", bound "//to_string(bound))
   end subroutine test_offset

   !> Linear elasticity: lengths x s give loads x s^2 and approaches x s.
   subroutine test_scaling(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: d
      call length_scaling(1.0e-3_dp, d, st)
      call check(error, st%code == 0 .and. d < 1.0e-12_dp, "s = 1e-3: "//to_string(d))
      if (allocated(error)) return
      call length_scaling(1.0e4_dp, d, st)
      call check(error, st%code == 0 .and. d < 1.0e-12_dp, "s = 1e4: "//to_string(d))
   end subroutine test_scaling

   !> nu -> 0.5 makes k ~ 1/(1 - 2 nu) huge: the incremental solver only gains accuracy
   !> (s -> 0; the spring compliance here is ~1e-13 of the substrate's); the legacy
   !> solver's error stays within eps x its condition estimate; nu = 0.5 itself is
   !> refused by the deck reader (test_deck).
   subroutine test_poisson(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: d, condition
      call poisson_limit("incremental", d, condition, st)
      call check(error, st%code == 0 .and. d < 1.0e-8_dp, "incremental vs rigid springs: "//to_string(d))
      if (allocated(error)) return
      call poisson_limit("legacy", d, condition, st)
      call check(error, st%code == 0 .and. d <= eps*condition, "legacy "//to_string(d)//" within eps x condition "// &
         to_string(eps*condition))
   end subroutine test_poisson

   !> Against real128: the coefficients femcod uses lose at most 2 digits anywhere (the
   !> four-corner sum alone loses ~2 log10(r) at r pixels, which the far-field expansion
   !> avoids); a 36-contact solve agrees to 1e-13.
   subroutine test_precision(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: offsets(2, 8) = reshape([0, 0, 1, 0, 1, 1, 5, 3, 19, 0, 50, 50, 200, 0, 1000, 700], [2, 8])
      real(dp) :: femcod, corners, far, df, da
      type(status_type) :: st
      integer :: k
      do k = 1, size(offsets, 2)
         call love_precision(offsets(1, k), offsets(2, k), femcod, corners, far)
         call check(error, femcod < 100*eps, "I("//to_string(offsets(1, k))//", "//to_string(offsets(2, k))// &
            "): relative error "//to_string(femcod))
         if (allocated(error)) return
      end do
      call love_precision(1000, 700, femcod, corners, far)
      call check(error, corners > 100*femcod, "the four-corner sum cancels at 1000 pixels: "//to_string(corners))
      if (allocated(error)) return
      call solve_precision(36, df, da, st)
      call check(error, st%code == 0 .and. df < 1.0e-13_dp .and. da < 1.0e-13_dp, "forces "//to_string(df)// &
         ", approach "//to_string(da))
   end subroutine test_precision

   !> The final check re-solves the end state afresh; doc/stability.md has the 5000-event run.
   subroutine test_drift(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st
      real(dp) :: drift, seconds
      integer :: steps
      call long_run_drift(2000, drift, steps, seconds, st)
      call check(error, st%code, 0, st%message)
      if (allocated(error)) return
      call check(error, steps >= 1000 .and. drift < 1.0e-10_dp, to_string(steps)//" steps, drift "//to_string(drift))
   end subroutine test_drift
end module test_stability
