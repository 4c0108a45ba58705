!> Adhesion under displacement control (`--adhesion`; the law in model/femcod_interface_law,
!> the iteration in solvers/femcod_gap_cg): a
!> paraboloid on a flat against the Maugis-Dugdale theory (Maugis 1992, its closed form in
!> model/femcod_analytic) in its DMT and JKR limits and between, zero work against the
!> event-exact solver, free and periodic, hysteresis on a rough surface, a periodic cell
!> against the free half-space, and the command line.
module test_adhesion
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result, cg_iterations_in_all
   use femcod_solver_options, only: contact_options, &
      SOLVER_INCREMENTAL, SOLVER_CG, BOUNDARY_FREE, BOUNDARY_PERIODIC, LAW_HARD_WALL, LAW_DUGDALE, LAW_EXPONENTIAL, boundary_name
   use femcod_solver, only: solve_contact
   use femcod_analytic, only: maugis_pull_off, maugis_at_load
   use femcod_generate, only: paraboloid_problem
   use femcod_scene, only: initial_gaps
   use test_cg, only: rough_scene
   use test_support, only: scratch_path, read_text, file_exists, remove_scratch
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_adhesion

   real(dp), parameter :: pi = 3.141592653589793238462643383279502884_dp

contains

   subroutine collect_adhesion(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("DMT limit: Maugis-Dugdale pull-off at lambda 0.1 within 1.5 %", test_dmt), &
         new_unittest("towards JKR: lambda 1, 2 converge to Maugis-Dugdale as the pixel halves", test_towards_jkr), &
         new_unittest("Maugis-Dugdale curve at lambda 1: contact radius and penetration at each load", &
            test_maugis_curve), &
         new_unittest("zero work: the non-adhesive cg answers; unloading retraces loading", test_zero_work), &
         new_unittest("rough surface: hysteresis between loading and unloading, pull-off", test_hysteresis), &
         new_unittest("periodic cell: a small sphere pulls off as on the free half-space", test_periodic_sphere), &
         new_unittest("plastic cap on the path: loading equals the event path, unloading the deformed surface", &
            test_plastic_path), &
         new_unittest("plastic flattening then adhesion: a larger pull-off", test_plastic_adhesion), &
         new_unittest("femcod run --adhesion: law and attractive area recorded; misuse refused (exit 2)", &
            test_run_adhesion) &
         ]
   end subroutine collect_adhesion

   !> The least load over the approaches of a paraboloid (E* = 1 GPa, W = 0.01 J/m^2) with
   !> the Dugdale range that gives the Maugis parameter lambda: loaded to 1 nm, then
   !> unloaded through `approaches`.
   subroutine sphere_pull_off(np, pixel, radius, lambda, approaches, pmin, status, iterations)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, radius, lambda, approaches(:)
      real(dp), intent(out) :: pmin
      type(status_type), intent(inout) :: status
      integer, intent(out) :: iterations
      type(contact_options) :: options
      type(contact_result) :: res
      real(dp), parameter :: young = 1, work = 0.01_dp
      type(contact_problem) :: scene
      options%solver = SOLVER_CG
      options%adhesion = LAW_DUGDALE
      options%work = work
      options%range = work/lambda*(9*radius/(2*pi*work*young**2))**(1.0_dp/3)
      options%approaches = [1.0_dp, approaches]
      scene = paraboloid_problem(np, pixel, radius, young)
      call solve_contact(scene, options, res, status)
      pmin = minval(res%states%load)/(pi*work*radius)
      iterations = cg_iterations_in_all(res)
   end subroutine sphere_pull_off

   !> DMT limit: lambda = 0.1, R = 100 nm, d = 1 nm. The least load over an unloading
   !> path (steps of 0.025 nm around the pull-off) against the Maugis-Dugdale least load
   !> for the same lambda, -1.9506 pi W R (2.5 % short of DMT's 2 pi W R, the lambda -> 0
   !> limit): measured -1.9629, 0.6 % off; the Dugdale zone's edge passes whole rings of
   !> pixels, so the load falls in steps of a few 0.01 pi W R.
   subroutine test_dmt(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: status
      real(dp) :: pmin, theory
      integer :: k, iterations
      theory = maugis_pull_off(0.1_dp)
      call check(error, abs(theory + 2) < 0.06_dp, "Maugis at lambda 0.1: "//to_string(theory)//", not near DMT's -2")
      if (allocated(error)) return
      call sphere_pull_off(64, 1.0_dp, 100.0_dp, 0.1_dp, [(-0.05_dp - 0.025_dp*k, k = 0, 12)], pmin, status, &
         iterations)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, pmin, theory, rel=.true., thr=0.015_dp, message="least load/(pi W R) "//to_string(pmin)// &
         " against Maugis-Dugdale "//to_string(theory))
   end subroutine test_dmt

   !> Towards JKR: lambda = 2 (Maugis-Dugdale least load -1.5346 pi W R, 2.3 % beyond
   !> JKR's -1.5 pi W R, the lambda -> infinity limit), R = 1000 nm, pixels of 2 and 1 nm.
   !> The Dugdale zone at pull-off is 4.3 nm wide: a coarse pixel pins the contact's edge
   !> and holds more tension. The error must fall as the pixel halves (first order:
   !> measured 0.289 -> 0.119 -> 0.061 -> 0.030 for d = 2, 1, 0.5, 0.25 nm, doc/solver.md),
   !> and the theory must lie within the finer grid's error estimate, the difference of
   !> the two grids (first-order convergence: the error of the finer one is about that).
   !> lambda = 1 the same way (least load -1.6007; measured errors 0.081, 0.030, 0.018).
   subroutine test_towards_jkr(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: status
      real(dp) :: coarse, fine, theory, lambda
      integer :: k, iterations, c
      do c = 1, 2
         lambda = real(3 - c, dp)
         theory = maugis_pull_off(lambda)
         call sphere_pull_off(64, 2.0_dp, 1000.0_dp, lambda, [(-0.2_dp - 0.05_dp*k, k = 0, 7)], coarse, status, &
            iterations)
         if (status%code == 0) call sphere_pull_off(128, 1.0_dp, 1000.0_dp, lambda, [(-0.2_dp - 0.05_dp*k, k = 0, 7)], &
            fine, status, iterations)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         call check(error, abs(fine - theory) < abs(coarse - theory), "lambda "//to_string(lambda)// &
            ": the error does not fall with the pixel: "//to_string(coarse)//", "//to_string(fine)//" against "// &
            to_string(theory))
         if (allocated(error)) return
         call check(error, abs(fine - theory) <= abs(fine - coarse), "lambda "//to_string(lambda)// &
            ": Maugis-Dugdale "//to_string(theory)//" outside the 1 nm grid's error estimate: "//to_string(fine)// &
            " +- "//to_string(abs(fine - coarse)))
         if (allocated(error)) return
      end do
      theory = maugis_pull_off(50.0_dp)
      call check(error, abs(theory + 1.5_dp) < 0.005_dp, "Maugis at lambda 50: "//to_string(theory)// &
         ", not near JKR's -1.5")
   end subroutine test_towards_jkr

   !> The Maugis-Dugdale curve at lambda = 1 (R = 1000 nm, d = 1 nm, 128^2 pixels): at the
   !> load each state carries, the theory's contact radius and penetration. Measured: radii
   !> within 0.8 % (the pixel count's radius sqrt(n d^2/pi)), penetrations within 0.018 nm
   !> (0.022 of the scale (pi^2 W^2 R/K^2)^(1/3) = 0.82 nm). At an approach of 2 nm the
   !> Dugdale zone reaches the grid's edge (not tested).
   subroutine test_maugis_curve(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp), parameter :: lambda = 1, radius = 1000, work = 0.01_dp, young = 1
      real(dp) :: pbar, abar, dbar, asc, dsc, a
      integer :: k
      type(contact_problem) :: scene
      options%solver = SOLVER_CG
      options%adhesion = LAW_DUGDALE
      options%work = work
      options%range = work/lambda*(9*radius/(2*pi*work*young**2))**(1.0_dp/3)
      options%approaches = [0.5_dp, 1.0_dp, 1.5_dp]
      scene = paraboloid_problem(128, 1.0_dp, radius, young)
      call solve_contact(scene, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      ! The scales of Johnson's notation, K = 4 E*/3.
      asc = (3*pi*work*radius**2/(4*young))**(1.0_dp/3)
      dsc = (9*pi**2*work**2*radius/(16*young**2))**(1.0_dp/3)
      do k = 1, size(res%states)
         pbar = res%states(k)%load/(pi*work*radius)
         call maugis_at_load(lambda, pbar, abar, dbar)
         a = sqrt(res%states(k)%contacts/pi)
         call check(error, a, abar*asc, rel=.true., thr=0.015_dp, message="contact radius at "// &
            to_string(res%states(k)%load)//" nN: "//to_string(a)//" nm against Maugis-Dugdale "//to_string(abar*asc))
         if (allocated(error)) return
         ! femcod's approach counts from the four central pixels' touch, d^2/(4R) after the apex's.
         call check(error, abs(res%states(k)%approach + 1/(4*radius) - dbar*dsc) < 0.03_dp*dsc, &
            "penetration at "//to_string(res%states(k)%load)//" nN: "//to_string(res%states(k)%approach)// &
            " nm against Maugis-Dugdale "//to_string(dbar*dsc))
         if (allocated(error)) return
      end do
   end subroutine test_maugis_curve

   !> Zero work of adhesion: the non-adhesive problem. On a 32 x 32 rough surface, free and
   !> periodic, the adhesive solver's loads and contacts at three approaches equal the
   !> event path's (--approach, no adhesion; exact on its piecewise-linear path) to 1e-9
   !> of the load (measured: 6e-12 free, 3e-11 periodic; tolerance 1e-10), and unloading
   !> retraces loading (no hysteresis).
   subroutine test_zero_work(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: plain, adhesive
      type(status_type) :: status
      real(dp), parameter :: d(3) = [0.7_dp, 1.2_dp, 2.0_dp]
      integer :: k, b
      call rough_scene(32, 5, deck)
      do b = 1, 2
         options = contact_options()
         ! The reference: the event path (exact on its piecewise-linear path).
         options%solver = SOLVER_INCREMENTAL
         options%boundary = merge(BOUNDARY_FREE, BOUNDARY_PERIODIC, b == 1)
         options%loads = [real(dp) ::]
         options%approaches = d
         call solve_contact(deck, options, plain, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         options%solver = SOLVER_CG
         options%adhesion = LAW_EXPONENTIAL
         options%work = 0
         options%range = 1
         options%cg%tol = 1.0e-10_dp
         options%approaches = [d, d(2:1:-1)]
         call solve_contact(deck, options, adhesive, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         do k = 1, 3
            call check(error, adhesive%states(k)%contacts, plain%states(k)%contacts, boundary_name(options%boundary)// &
               ": contacts at "//to_string(d(k)))
            if (allocated(error)) return
            call check(error, adhesive%states(k)%load, plain%states(k)%load, rel=.true., thr=1.0e-9_dp, &
               message=boundary_name(options%boundary)//": load at "//to_string(d(k)))
            if (allocated(error)) return
         end do
         do k = 1, 2
            call check(error, adhesive%states(3 + k)%load, adhesive%states(3 - k)%load, rel=.true., thr=1.0e-8_dp, &
               message=boundary_name(options%boundary)//": unloading to "//to_string(d(3 - k))//" does not retrace loading")
            if (allocated(error)) return
         end do
      end do
   end subroutine test_zero_work

   !> Hysteresis on a rough surface (64 x 64, E = 10 GPa, exponential law, W = 0.5 J/m^2,
   !> range 1 nm), along -6, 1, 4, 1, -6 nm: far apart the surfaces attract a little and
   !> do not touch; at 1 nm the contact appears (a jump from none); back at 1 nm from
   !> 4 nm adhesion holds more contact and pulls harder than on the way in (measured: 953
   !> against 924 pixels, -17281 against -16815 nN; required: more pixels and 1 % more
   !> pull); at -6 nm every contact has let go (pull-off) and the state equals the first
   !> one (the only state so far apart) to 1e-7 (tolerance 1e-10; measured 8e-9); every
   !> state converged.
   subroutine test_hysteresis(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      call rough_scene(64, 3, deck)
      deck%young(1) = 10
      options%solver = SOLVER_CG
      options%adhesion = LAW_EXPONENTIAL
      options%work = 0.5_dp
      options%range = 1
      options%approaches = [-6.0_dp, 1.0_dp, 4.0_dp, 1.0_dp, -6.0_dp]
      options%cg%tol = 1.0e-10_dp
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, res%states(1)%contacts == 0 .and. res%states(1)%load < 0, "at -6 nm: "// &
         to_string(res%states(1)%contacts)//" contacts, load "//to_string(res%states(1)%load))
      if (allocated(error)) return
      call check(error, res%states(2)%jump, 1, "no jump into contact reported at 1 nm")
      if (allocated(error)) return
      call check(error, res%states(4)%load < 1.01_dp*res%states(2)%load .and. &
         res%states(4)%contacts > res%states(2)%contacts, "at 1 nm: unloading "//to_string(res%states(4)%load)// &
         " nN on "//to_string(res%states(4)%contacts)//" pixels, loading "//to_string(res%states(2)%load)// &
         " nN on "//to_string(res%states(2)%contacts))
      if (allocated(error)) return
      call check(error, res%states(5)%contacts == 0 .and. res%states(5)%jump == -1, "no pull-off at -6 nm")
      if (allocated(error)) return
      call check(error, res%states(5)%load, res%states(1)%load, rel=.true., thr=1.0e-7_dp, &
         message="at -6 nm, unloaded against the first state")
   end subroutine test_hysteresis

   !> A periodic cell much larger than the contact: the sphere at lambda = 0.5 (R = 100 nm,
   !> d = 1 nm, 64^2) pulls off with the free half-space's least load within 1 % (measured
   !> 0.6 %: the images 64 nm away add a displacement nearly uniform over the contact).
   subroutine test_periodic_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      type(contact_result) :: free, periodic
      type(status_type) :: status
      real(dp), parameter :: radius = 100, work = 0.01_dp, young = 1, lambda = 0.5_dp
      integer :: k
      type(contact_problem) :: scene
      options%solver = SOLVER_CG
      options%adhesion = LAW_DUGDALE
      options%work = work
      options%range = work/lambda*(9*radius/(2*pi*work*young**2))**(1.0_dp/3)
      options%approaches = [1.0_dp, (-0.05_dp*k, k = 1, 10)]
      scene = paraboloid_problem(64, 1.0_dp, radius, young)
      call solve_contact(scene, options, free, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      options%boundary = BOUNDARY_PERIODIC
      call solve_contact(scene, options, periodic, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, minval(periodic%states%load), minval(free%states%load), rel=.true., thr=0.01_dp, &
         message="least load, periodic against free")
   end subroutine test_periodic_sphere

   !> The plastic cap on the path (W = 0: the non-adhesive interface), on a 32 x 32 rough
   !> surface with H = 20 GPa. Loading to 0.7, 1.2, 2 nm: the states equal the event path's
   !> (--plastic --approach, exact; it too keeps a capped pixel's plastic displacement) to
   !> 1e-8 of the load, with the same plastic pixels. Unloading to 1.2 and 0.7 nm and
   !> below first touch: the interface is elastic again, so each state equals the event
   !> path's elastic state on the surface deformed by the plastic displacement of the
   !> path (the heights lowered by it, the approach shifted by the fall of the highest
   !> point), to 1e-8; at -0.5 nm no load, the plastic displacement kept.
   subroutine test_plastic_path(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck, deformed
      type(contact_options) :: options
      type(contact_result) :: path, exact, elastic
      type(status_type) :: status
      real(dp), parameter :: up(3) = [0.7_dp, 1.2_dp, 2.0_dp], down(3) = [1.2_dp, 0.7_dp, -0.5_dp]
      real(dp), allocatable :: total(:, :), plastic(:, :)
      real(dp) :: shift
      integer :: k
      call rough_scene(32, 5, deck)
      options%solver = SOLVER_CG
      options%loads = [real(dp) ::]
      options%plastic = .true.
      options%hardness = 20
      options%adhesion = LAW_DUGDALE
      options%work = 0
      options%range = 1
      options%cg%tol = 1.0e-11_dp
      options%approaches = [up, down]
      call solve_contact(deck, options, path, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, path%states(3)%n_plastic > 0, "no plastic pixel at 2 nm")
      if (allocated(error)) return
      options%solver = SOLVER_INCREMENTAL
      options%adhesion = LAW_HARD_WALL
      options%approaches = up
      call solve_contact(deck, options, exact, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      do k = 1, 3
         call check(error, path%states(k)%n_plastic, exact%states(k)%n_plastic, "plastic pixels at "// &
            to_string(up(k)))
         if (allocated(error)) return
         call check(error, path%states(k)%contacts, exact%states(k)%contacts, "contacts at "//to_string(up(k)))
         if (allocated(error)) return
         call check(error, path%states(k)%load, exact%states(k)%load, rel=.true., thr=1.0e-8_dp, &
            message="load at "//to_string(up(k)))
         if (allocated(error)) return
      end do
      ! The cap is the law's bound: a capped pixel carries H d^2 exactly, none more (the
      ! event path's reading; this path reported 11.000000000000028 GPa and pixels above
      ! H before, issue 34).
      do k = 1, size(path%states)
         if (path%states(k)%n_plastic == 0) cycle
         call check(error, path%states(k)%max_pressure == options%hardness .and. &
            path%states(k)%n_above_hardness == 0, "state "//to_string(k)//": max pressure "// &
            to_string(path%states(k)%max_pressure)//" GPa, "//to_string(path%states(k)%n_above_hardness)// &
            " pixels above H = "//to_string(options%hardness))
         if (allocated(error)) return
      end do
      ! The surface deformed by the path's plastic displacement (shape on the lower body).
      plastic = path%states(6)%plastic
      deformed = deck
      deformed%lower = deck%lower - plastic
      ! The deformed gaps are g0 + plastic - shift (shift: how far the highest point fell),
      ! so the approach A of the path is A - shift there.
      total = transpose(reshape(initial_gaps(deck%lower, deck%upper), [32, 32]))
      shift = maxval(transpose(reshape(initial_gaps(deformed%lower, deformed%upper), [32, 32])) - total - plastic)
      options%plastic = .false.
      options%approaches = down + shift
      call solve_contact(deformed, options, elastic, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      do k = 1, 3
         call check(error, path%states(3 + k)%contacts, elastic%states(k)%contacts, "unloading: contacts at "// &
            to_string(down(k)))
         if (allocated(error)) return
         call check(error, abs(path%states(3 + k)%load - elastic%states(k)%load) <= 1.0e-8_dp*path%states(3)%load, &
            "unloading: load at "//to_string(down(k))//": "//to_string(path%states(3 + k)%load)//" against "// &
            to_string(elastic%states(k)%load))
         if (allocated(error)) return
         call check(error, path%states(3 + k)%n_plastic, 0, "unloading: pixels still at the cap")
         if (allocated(error)) return
      end do
      call check(error, path%states(6)%plastic_volume, path%states(3)%plastic_volume, rel=.true., thr=1.0e-12_dp, &
         message="the plastic volume changed on unloading")
   end subroutine test_plastic_path

   !> Adhesion after plastic flattening: the lambda = 1 sphere (R = 1000 nm, d = 2 nm)
   !> loaded to 1 nm with a hardness the contact reaches (0.015 GPa, E* = 1 GPa; Hertz's
   !> peak there is 0.020 GPa) and unloaded
   !> pulls off harder than without the cap (the flattened contact is wider: Maugis and
   !> Pollock 1984; measured -66.3 against -51.7 nN, 1004 of 1828 contact pixels capped at
   !> 1 nm), and keeps its plastic volume.
   subroutine test_plastic_adhesion(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      type(contact_result) :: capped, elastic
      type(status_type) :: status
      real(dp), parameter :: radius = 1000, work = 0.01_dp, young = 1, lambda = 1
      integer :: k
      type(contact_problem) :: scene
      options%solver = SOLVER_CG
      options%adhesion = LAW_DUGDALE
      options%work = work
      options%range = work/lambda*(9*radius/(2*pi*work*young**2))**(1.0_dp/3)
      options%approaches = [1.0_dp, (-0.1_dp*k, k = 0, 12)]
      scene = paraboloid_problem(64, 2.0_dp, radius, young)
      call solve_contact(scene, options, elastic, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      options%plastic = .true.
      options%hardness = 0.015_dp
      call solve_contact(scene, options, capped, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, capped%states(1)%n_plastic > 0, "no pixel reached the hardness at 1 nm")
      if (allocated(error)) return
      call check(error, minval(capped%states%load) < 1.05_dp*minval(elastic%states%load), "pull-off "// &
         to_string(minval(capped%states%load))//" nN with the cap, "//to_string(minval(elastic%states%load))// &
         " without")
      if (allocated(error)) return
      call check(error, capped%states(size(capped%states))%plastic_volume > 0, "no plastic volume left")
   end subroutine test_plastic_adhesion

   !> From the command line: a Dugdale run on the thesis' sphere deck (exit 0) records the
   !> law in the summary file and /run, each approach's attractive pixels and mean gap
   !> in the summary file, and pull-off as a jump; what does not apply is refused with
   !> exit code 2 and writes nothing: --adhesion without --approach, with the incremental
   !> solver, with the shear model, without --range; --work without --adhesion.
   subroutine test_run_adhesion(error)
      type(error_type), allocatable, intent(out) :: error
      type(string_type), allocatable :: base(:)
      character(len=:), allocatable :: prefix, json
      integer :: code, k
      type :: refusal
         type(string_type), allocatable :: extra(:)
      end type refusal
      type(refusal) :: cases(5)
      prefix = scratch_path("adhesion-run")
      base = [string_type("run"), string_type("input/sphere_d1.deck"), string_type("-o"), string_type(prefix), &
         string_type("--quiet"), string_type("--force")]
      call run_femcod([base, string_type("--solver"), string_type("cg"), string_type("--adhesion"), &
         string_type("dugdale"), string_type("--work"), string_type("1"), string_type("--range"), string_type("0.5"), &
         string_type("--approach"), string_type("0.5,0,-0.5")], code)
      call check(error, code, 0, "the adhesive run")
      if (allocated(error)) return
      json = read_text(prefix//".summary.json")
      call check(error, index(json, '"adhesion": {"law": "dugdale"') > 0 .and. index(json, '"attractive_pixels": ') > 0 &
         .and. index(json, '"mean_gap_nm": ') > 0 .and. index(json, '"jump": -1') > 0, "the summary file: "//json)
      if (allocated(error)) return
      cases(1)%extra = [string_type("--solver"), string_type("cg"), string_type("--adhesion"), string_type("dugdale"), &
         string_type("--work"), string_type("1"), string_type("--range"), string_type("0.5"), string_type("--loads"), &
         string_type("10")]
      cases(2)%extra = [string_type("--adhesion"), string_type("dugdale"), string_type("--work"), string_type("1"), &
         string_type("--range"), string_type("0.5"), string_type("--approach"), string_type("0.5")]
      cases(3)%extra = [cases(1)%extra(1:8), string_type("--shear-strength"), string_type("0.1"), &
         string_type("--approach"), string_type("0.5")]
      cases(4)%extra = [cases(1)%extra(1:6), string_type("--approach"), string_type("0.5")]
      cases(5)%extra = [string_type("--solver"), string_type("cg"), string_type("--work"), string_type("1"), &
         string_type("--approach"), string_type("0.5")]
      do k = 1, size(cases)
         call remove_scratch(prefix//".h5")
         call run_femcod([base, cases(k)%extra], code)
         call check(error, code, 2, "refusal "//to_string(k))
         if (allocated(error)) return
         call check(error, .not. file_exists(prefix//".h5"), "refusal "//to_string(k)//" wrote results")
         if (allocated(error)) return
      end do
   end subroutine test_run_adhesion
end module test_adhesion
