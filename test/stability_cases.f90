!> Numerical stability on hard cases (doc/stability.md): each routine builds a scene,
!> runs the solvers and returns the measured error against an expected value from
!> analysis or an independent computation (test/oracles; never femcod's own checks of
!> itself). The stability suite asserts bounds on these numbers; the test driver's
!> --stability-report tabulates them. No I/O here.
module stability_cases
   use, intrinsic :: iso_fortran_env, only: real128
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem, verification_spec
   use femcod_contact_result, only: contact_result
   use test_support, only: pivot_loss_of, missed_final_check_of
   use femcod_solver_options, only: contact_options, solver_from_name
   use femcod_solver, only: solve_contact
   use femcod_condensed, only: solve_active_set
   use femcod_love, only: offset_table, love_influence, love_influence_exact, love_influence_far
   use oracles, only: love_quad, love_table, composite_compliance, spring_compliance, reference_gaps, exact_state, &
      appendix_b_condition
   implicit none
   private
   public :: stiffness_row, stiffness_sweep, symmetry_defect, symmetric_scene, flat_on_flat, single_pixel, &
      first_spike_event, identical_surfaces, height_offset, length_scaling, poisson_limit, love_precision, &
      solve_precision, long_run_drift, solve, STIFFNESS_RATIOS, INCOMPRESSIBLE_GAP, legacy_condition

   !> Penalty/interface stiffness over the substrate's, swept by stiffness_sweep.
   real(dp), parameter :: STIFFNESS_RATIOS(6) = [1.0e2_dp, 1.0e4_dp, 1.0e6_dp, 1.0e8_dp, 1.0e10_dp, 1.0e12_dp]
   !> 0.5 - nu of the near-incompressible contact elements of poisson_limit.
   real(dp), parameter :: INCOMPRESSIBLE_GAP = 1.0e-9_dp

   !> One row of the stiffness sweep: relative approach errors at 1000 nN against the
   !> rigid-spring limit, and TRFACT's pivot loss.
   type :: stiffness_row
      real(dp) :: ratio = 0
      !> Incremental and legacy against the rigid-spring limit; legacy against the
      !> incremental solution of the same model (round-off only).
      real(dp) :: incremental = 0, legacy = 0, legacy_roundoff = 0, pivot_loss = 0, condition = 0
   end type stiffness_row

contains

   !> Run one solver on a deck at the given loads.
   subroutine solve(deck, solver, loads, res, status, max_contacts)
      type(contact_problem), intent(inout) :: deck
      character(len=*), intent(in) :: solver
      real(dp), intent(in) :: loads(:)
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      integer, intent(in), optional :: max_contacts
      type(contact_options) :: options
      options%loads = loads
      if (present(max_contacts)) options%max_contacts = max_contacts
      options%solver = solver_from_name(solver)
      call solve_contact(deck, options, res, status)
   end subroutine solve

   !> The rigid sphere of Fig. 4.15 at d = 2 nm (input/sphere_d2.deck) with the contact
   !> and interface elements `ratio` times stiffer than the substrate, at 1000 nN.
   !> The reference is the same scene with rigid springs (E3 = 1e300 GPa: s = 3/k ~ 1e-300).
   !> Analysis: the approach per unit load is delta(s) = min over f (1'f = 1) of
   !> f'(cK + sI)f, so 0 <= delta(s) - delta(0) <= s |f|^2: the model error is positive and
   !> linear in s ~ 1/ratio; the legacy path adds round-off ~ eps * pivot loss.
   subroutine stiffness_sweep(rows, status)
      type(stiffness_row), intent(out) :: rows(size(STIFFNESS_RATIOS))
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_result) :: res
      real(dp) :: reference, inc
      integer :: k
      call verification_spec("sphere_d2", spec, status)
      call build_problem(spec, deck, status)
      if (status%code /= 0) return
      deck%young(3) = 1.0e300_dp
      call solve(deck, "incremental", [1000.0_dp], res, status)
      if (status%code /= 0) return
      reference = res%states(1)%approach
      do k = 1, size(STIFFNESS_RATIOS)
         rows(k)%ratio = STIFFNESS_RATIOS(k)
         deck%young(3) = deck%young(1)*STIFFNESS_RATIOS(k)
         call solve(deck, "incremental", [1000.0_dp], res, status)
         if (status%code /= 0) return
         inc = res%states(1)%approach
         rows(k)%incremental = (inc - reference)/reference
         call solve(deck, "legacy", [1000.0_dp], res, status)
         if (status%code /= 0) return
         rows(k)%legacy = (res%states(1)%approach - reference)/reference
         rows(k)%legacy_roundoff = abs(res%states(1)%approach - inc)/inc
         rows(k)%pivot_loss = pivot_loss_of(res)
         rows(k)%condition = legacy_condition(deck, res)
      end do
   end subroutine stiffness_sweep

   !> The largest exact condition number of the Appendix B systems the legacy solver
   !> factorised for `res`: at step s the contacts that joined up to s (test/oracles).
   function legacy_condition(deck, res) result(kappa)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      real(dp) :: kappa
      real(dp), allocatable :: table(:, :)
      logical, allocatable :: joined(:)
      integer :: s
      table = love_table(deck%np)
      kappa = 0
      do s = 1, maxval(res%contact_step)
         joined = res%contact_step <= s
         kappa = max(kappa, appendix_b_condition(deck, table, pack(res%contact_i, joined), pack(res%contact_j, joined)))
      end do
   end function legacy_condition

   !> Scenes with the symmetry of the square (D4): "sphere-centre" (apex on a pixel
   !> centre, NP = 15), "sphere-corner" (apex on a pixel corner, NP = 16), "square-punch"
   !> (input/square_punch_n9), "sinusoid" (eq. 3.3, A = 1 nm, w = 10 nm, NP = 31).
   subroutine symmetric_scene(name, deck, status)
      character(len=*), intent(in) :: name
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      select case (name)
      case ("sphere-centre")
         call verification_spec("sphere_d2", spec, status)
      case ("sphere-corner")
         call verification_spec("sphere_d2", spec, status)
         spec%np = 16
      case ("square-punch")
         call verification_spec("square_punch_n9", spec, status)
      case default
         spec%kind = "sinusoid"
         spec%label = "sinusoid eq. 3.3"
         spec%matrix_file = ""
         spec%np = 31
         spec%pixel = 1
         spec%amplitude = 1
         spec%scale = 10
         spec%maxcont = 120
      end select
      call build_problem(spec, deck, status)
   end subroutine symmetric_scene

   !> Largest asymmetry of the contact forces over the history: the deck is solved once,
   !> then again with a requested load inside every step (the state there is exact; a
   !> step of zero length has none),
   !> and each force map F is compared with its images under the eight symmetries of
   !> the square: max |F - T(F)| / max F. `sets` counts states whose contact set is
   !> not symmetric.
   subroutine symmetry_defect(deck, solver, defect, sets, nstates, status)
      type(contact_problem), intent(inout) :: deck
      character(len=*), intent(in) :: solver
      real(dp), intent(out) :: defect
      integer, intent(out) :: sets, nstates
      type(status_type), intent(inout) :: status
      type(contact_result) :: res
      real(dp), allocatable :: loads(:), map(:, :), image(:, :)
      integer :: k, m, op, np
      defect = 0
      sets = 0
      nstates = 0
      call solve(deck, solver, [real(dp) ::], res, status)
      if (status%code /= 0) return
      ! A load inside every step: step k runs from the load where step k-1 ended (0 for
      ! the first) to step_load(k).
      m = res%nsteps
      allocate(loads(m))
      loads(1) = res%step_load(1)/2
      do k = 2, m
         loads(k) = (res%step_load(k - 1) + res%step_load(k))/2
      end do
      call solve(deck, solver, loads, res, status)
      if (status%code /= 0) return
      np = deck%np
      allocate(map(np, np))
      do k = 1, m
         if (.not. res%states(k)%reached) cycle
         if (res%states(k)%load <= 0) cycle
         nstates = nstates + 1
         map = 0
         call scatter(res%states(k)%i, res%states(k)%j, res%states(k)%force, map)
         do op = 1, 7
            image = transformed(map, op)
            defect = max(defect, maxval(abs(map - image))/maxval(map))
            if (any((map > 0) .neqv. (image > 0))) sets = sets + 1
         end do
      end do
   contains
      subroutine scatter(i, j, f, field)
         integer, intent(in) :: i(:), j(:)
         real(dp), intent(in) :: f(:)
         real(dp), intent(inout) :: field(:, :)
         integer :: q
         field = 0
         do q = 1, size(f)
            field(i(q), j(q)) = f(q)
         end do
      end subroutine scatter
   end subroutine symmetry_defect

   !> The seven non-trivial symmetries of the square grid.
   pure function transformed(a, op) result(b)
      real(dp), intent(in) :: a(:, :)
      integer, intent(in) :: op
      real(dp) :: b(size(a, 1), size(a, 2))
      integer :: n
      n = size(a, 1)
      select case (op)
      case (1)
         b = a(n:1:-1, :)
      case (2)
         b = a(:, n:1:-1)
      case (3)
         b = a(n:1:-1, n:1:-1)
      case (4)
         b = transpose(a)
      case (5)
         b = transpose(a(n:1:-1, n:1:-1))
      case (6)
         b = transpose(a(n:1:-1, :))
      case default
         b = transpose(a(:, n:1:-1))
      end select
   end function transformed

   !> Flat on flat: every pixel touches at zero load, so the first step holds all NP^2
   !> contacts and the scene is the rigid square punch covering the grid. Returns the
   !> contacts of the first step, the relative difference of the approach at 100 nN from
   !> an independent dense solve (test/oracles), and the legacy system's exact condition.
   subroutine flat_on_flat(solver, first_contacts, difference, condition, status)
      character(len=*), intent(in) :: solver
      integer, intent(out) :: first_contacts
      real(dp), intent(out) :: difference, condition
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_result) :: res
      real(dp), allocatable :: forces(:)
      integer, allocatable :: ic(:), jc(:)
      real(dp) :: approach
      integer :: i, j, np, info
      spec%kind = "flat"
      spec%label = "flat on flat"
      spec%matrix_file = ""
      spec%np = 8
      spec%pixel = 1
      call build_problem(spec, deck, status)
      call solve(deck, solver, [100.0_dp], res, status)
      if (status%code /= 0) return
      first_contacts = res%step_contacts(1)
      condition = legacy_condition(deck, res)
      np = deck%np
      allocate(ic(np*np), jc(np*np), forces(np*np))
      do i = 1, np
         do j = 1, np
            ic((i - 1)*np + j) = i
            jc((i - 1)*np + j) = j
         end do
      end do
      call exact_state(deck, love_table(np), ic, jc, 100.0_dp, forces, approach, info)
      difference = abs(res%states(1)%approach - approach)/approach
   end subroutine flat_on_flat

   !> NP = 1 with Poisson's ratio `nu` for every material: one contact, and the approach
   !> at 7 nN is exactly 7 (c I(0,0) + 3/k) (relative difference returned).
   subroutine single_pixel(solver, nu, difference, status)
      character(len=*), intent(in) :: solver
      real(dp), intent(in) :: nu
      real(dp), intent(out) :: difference
      type(status_type), intent(inout) :: status
      type(contact_problem) :: deck
      type(contact_result) :: res
      real(dp) :: expected
      deck%label = "one pixel"
      deck%np = 1
      deck%pixel = 3
      deck%maxcont = 1
      deck%young = [200.0_dp, 2.0e6_dp, 2.0e6_dp]
      deck%poisson = nu
      allocate(deck%lower(1, 1), deck%upper(1, 1))
      deck%lower = 5
      deck%upper = 0
      call solve(deck, solver, [7.0_dp], res, status)
      if (status%code /= 0) return
      ! The closed forms of test/oracles: c I(0,0) + 3/k per nN.
      expected = 7*(composite_compliance(deck)*real(love_quad(0.0_real128, 0.0_real128), dp) + &
         3*spring_compliance(deck))
      difference = abs(res%states(1)%approach - expected)/expected
   end subroutine single_pixel

   !> A rough surface (rms 1 nm) with one spike 1000 nm high: the spike carries the load
   !> alone until the next pixel closes, at the load min_p g_p / (self - c I(p - spike))
   !> (closed form over all pixels). Returns the relative difference of the solver's
   !> first event load from it.
   subroutine first_spike_event(solver, difference, missed, status)
      character(len=*), intent(in) :: solver
      real(dp), intent(out) :: difference
      !> Pixels found penetrating by the final check (the legacy candidate list misses).
      integer, intent(out) :: missed
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_result) :: res
      real(dp), allocatable :: table(:, :), g0(:, :)
      real(dp) :: c, self, best
      integer :: i, j, np
      spec%kind = "self-affine"
      spec%label = "spike"
      spec%matrix_file = ""
      spec%np = 24
      spec%pixel = 10
      spec%rms = 1
      spec%shape_on = "lower"
      call build_problem(spec, deck, status)
      if (status%code /= 0) return
      deck%lower(7, 11) = deck%lower(7, 11) + 1000
      call solve(deck, solver, [real(dp) ::], res, status, max_contacts=3)
      if (status%code /= 0) return
      missed = missed_final_check_of(res)
      np = deck%np
      ! The closed form with the oracles' coefficients and gaps (test/oracles).
      allocate(table(0:np - 1, 0:np - 1))
      table = love_table(np)
      c = composite_compliance(deck)
      self = c*table(0, 0) + 3*spring_compliance(deck)
      g0 = reference_gaps(deck)
      best = huge(1.0_dp)
      do j = 1, np
         do i = 1, np
            if (i == 7 .and. j == 11) cycle
            best = min(best, g0(i, j)/(self - c*table(abs(i - 7), abs(j - 11))))
         end do
      end do
      difference = abs(res%step_load(1) - best)/best
   end subroutine first_spike_event

   !> Two identical elastic rough surfaces (rigid none) against the single surface
   !> hl + flip(hu) on an elastic flat of the same material: the gaps and the composite
   !> compliance are the same, so the histories must be. Largest relative difference of
   !> the step loads and approaches.
   subroutine identical_surfaces(difference, status)
      real(dp), intent(out) :: difference
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: twin, single
      type(contact_result) :: a, b
      spec%kind = "self-affine"
      spec%label = "identical rough surfaces"
      spec%matrix_file = ""
      spec%np = 24
      spec%pixel = 10
      spec%rms = 3
      spec%rigid = "none"
      spec%maxcont = 60
      call build_problem(spec, twin, status)
      if (status%code /= 0) return
      twin%lower = twin%upper
      single = twin
      single%lower = twin%lower + twin%upper(twin%np:1:-1, :)
      single%upper = 0
      call solve(twin, "incremental", [real(dp) ::], a, status)
      call solve(single, "incremental", [real(dp) ::], b, status)
      if (status%code /= 0) return
      difference = history_difference(a, b, 1.0_dp, 1.0_dp)
   end subroutine identical_surfaces

   !> Largest relative difference between two histories, the second scaled back by the
   !> load and length factors (steps must agree in number and contacts, else 1).
   pure real(dp) function history_difference(a, b, load_factor, length_factor) result(d)
      type(contact_result), intent(in) :: a, b
      real(dp), intent(in) :: load_factor, length_factor
      integer :: n
      d = 1
      if (a%nsteps /= b%nsteps .or. a%nsteps == 0) return
      n = a%nsteps
      if (any(a%step_contacts(1:n) /= b%step_contacts(1:n))) return
      d = max(maxval(abs(a%step_load(1:n) - b%step_load(1:n)/load_factor))/maxval(abs(a%step_load(1:n))), &
         maxval(abs(a%step_approach(1:n) - b%step_approach(1:n)/length_factor))/maxval(abs(a%step_approach(1:n))))
   end function history_difference

   !> Roughness of 1e-3 nm rms on heights offset by 1e6 nm, against the same roughness
   !> without the offset. The offset heights carry an absolute rounding of up to half an
   !> ulp of 1e6 (5.8e-11 nm), 6e-8 of the roughness: that is the accuracy the input
   !> allows. Returns the largest relative difference of the histories and that bound.
   subroutine height_offset(difference, bound, status)
      real(dp), intent(out) :: difference, bound
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: plain, offset
      type(contact_result) :: a, b
      real(dp), allocatable :: g0(:, :)
      real(dp) :: gmin
      integer :: k
      spec%kind = "self-affine"
      spec%label = "1e-3 nm roughness"
      spec%matrix_file = ""
      spec%np = 24
      spec%pixel = 1
      spec%rms = 1.0e-3_dp
      spec%shape_on = "lower"
      spec%maxcont = 40
      call build_problem(spec, plain, status)
      if (status%code /= 0) return
      offset = plain
      offset%lower = plain%lower + 1.0e6_dp
      offset%upper = plain%upper + 1.0e6_dp
      call solve(plain, "incremental", [real(dp) ::], a, status)
      call solve(offset, "incremental", [real(dp) ::], b, status)
      if (status%code /= 0) return
      difference = history_difference(a, b, 1.0_dp, 1.0_dp)
      ! Four rounded heights per gap (two per surface), each off by up to half an ulp of
      ! 1e6; the loads scale with the gaps that close, the smallest of which is g_min.
      g0 = reference_gaps(plain)
      gmin = huge(1.0_dp)
      do k = 1, size(a%contact_i)
         associate(g => g0(a%contact_i(k), a%contact_j(k)))
            if (g > 0) gmin = min(gmin, g)
         end associate
      end do
      bound = 4*(spacing(1.0e6_dp)/2)/gmin
   end subroutine height_offset

   !> The same rough scene with every length scaled by `factor` (pixel and heights):
   !> linear elasticity gives loads x factor^2 and approaches x factor at every step.
   !> Largest relative difference after scaling back.
   subroutine length_scaling(factor, difference, status)
      real(dp), intent(in) :: factor
      real(dp), intent(out) :: difference
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: base, scaled
      type(contact_result) :: a, b
      spec%kind = "self-affine"
      spec%label = "scaling"
      spec%matrix_file = ""
      spec%np = 24
      spec%pixel = 1
      spec%rms = 0.3_dp
      spec%maxcont = 40
      call build_problem(spec, base, status)
      if (status%code /= 0) return
      scaled = base
      scaled%pixel = base%pixel*factor
      scaled%lower = base%lower*factor
      scaled%upper = base%upper*factor
      call solve(base, "incremental", [real(dp) ::], a, status)
      call solve(scaled, "incremental", [real(dp) ::], b, status)
      if (status%code /= 0) return
      difference = history_difference(a, b, factor**2, factor)
   end subroutine length_scaling

   !> Contact and interface elements with nu = 0.5 - INCOMPRESSIBLE_GAP: k carries
   !> 1/(1 - 2 nu) = 5e8, so the springs are ~1e13 times stiffer than the substrate.
   !> Relative approach difference at 1000 nN from the rigid-spring limit (sphere d = 2).
   subroutine poisson_limit(solver, difference, condition, status)
      character(len=*), intent(in) :: solver
      real(dp), intent(out) :: difference, condition
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_result) :: res
      real(dp) :: reference
      call verification_spec("sphere_d2", spec, status)
      call build_problem(spec, deck, status)
      if (status%code /= 0) return
      deck%young(3) = 1.0e300_dp
      call solve(deck, "incremental", [1000.0_dp], res, status)
      if (status%code /= 0) return
      reference = res%states(1)%approach
      deck%young(3) = deck%young(1)*1.0e5_dp
      deck%poisson(3) = 0.5_dp - INCOMPRESSIBLE_GAP
      call solve(deck, solver, [1000.0_dp], res, status)
      if (status%code /= 0) return
      difference = abs(res%states(1)%approach - reference)/reference
      condition = legacy_condition(deck, res)
   end subroutine poisson_limit

   !> The Love coefficient at offset (p, q) in double (femcod's choice, the four-corner
   !> sum and the far-field expansion) against the four-corner sum in quadruple
   !> precision: relative errors.
   subroutine love_precision(p, q, femcod, corners, far)
      integer, intent(in) :: p, q
      real(dp), intent(out) :: femcod, corners, far
      real(real128) :: exact
      exact = love_quad(real(min(abs(p), abs(q)), real128), real(max(abs(p), abs(q)), real128))
      femcod = real(abs(love_influence(p, q) - exact)/exact, dp)
      corners = real(abs(love_influence_exact(real(min(p, q), dp), real(max(p, q), dp)) - exact)/exact, dp)
      ! The expansion is in 1/r: not defined at offset zero (reported as -1).
      far = -1
      if (p /= 0 .or. q /= 0) &
         far = real(abs(love_influence_far(real(min(p, q), dp), real(max(p, q), dp)) - exact)/exact, dp)
   end subroutine love_precision

   !> A contact cluster (`n` pixels in a compact block) under unit load: the forces
   !> from the double-precision dsysv solve of femcod's active-set system against a
   !> quadruple-precision Cholesky solve of the same equations (coefficients in
   !> quadruple). Returns the relative difference of the forces and of the approach.
   subroutine solve_precision(n, forces_error, approach_error, status)
      integer, intent(in) :: n
      real(dp), intent(out) :: forces_error, approach_error
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: table(:, :), forces(:)
      real(real128), allocatable :: m(:, :), x(:)
      integer, allocatable :: ic(:), jc(:)
      real(dp) :: approach
      real(real128) :: beta, sq
      integer :: k, l, side, a, b
      side = ceiling(sqrt(real(n, dp)))
      allocate(ic(n), jc(n), forces(n), table(0:side, 0:side), m(n, n), x(n))
      do k = 1, n
         ic(k) = (k - 1)/side + 1
         jc(k) = k - (ic(k) - 1)*side
      end do
      table = offset_table(side + 1)
      call solve_active_set(ic, jc, [(0.0_dp, k = 1, n)], 1.0_dp, 0.0_dp, table, 1.0_dp, forces, approach, status)
      if (status%code /= 0) return
      ! Quadruple: M x = 1 by Cholesky, F = x / 1'x, approach = 1 / 1'x.
      do l = 1, n
         do k = 1, n
            m(k, l) = love_quad(real(min(abs(ic(k) - ic(l)), abs(jc(k) - jc(l))), real128), &
               real(max(abs(ic(k) - ic(l)), abs(jc(k) - jc(l))), real128))
         end do
      end do
      do l = 1, n
         sq = m(l, l) - sum(m(1:l - 1, l)**2)
         m(l, l) = sqrt(sq)
         do b = l + 1, n
            m(l, b) = (m(l, b) - sum(m(1:l - 1, l)*m(1:l - 1, b)))/m(l, l)
         end do
      end do
      x = 1
      do a = 1, n
         x(a) = (x(a) - sum(m(1:a - 1, a)*x(1:a - 1)))/m(a, a)
      end do
      do a = n, 1, -1
         x(a) = (x(a) - sum(m(a, a + 1:n)*x(a + 1:n)))/m(a, a)
      end do
      beta = sum(x)
      forces_error = real(maxval(abs(forces - x/beta))/maxval(abs(x/beta)), dp)
      approach_error = real(abs(approach - 1/beta)*beta, dp)
   end subroutine solve_precision

   !> A long run: `events` contacts on a 100 x 100 self-affine surface (rms 3 nm, 5 nm
   !> pixels); the accumulated approach and forces at the end against the exact state of
   !> the final contact set (test/oracles' dense solve).
   subroutine long_run_drift(events, drift, steps, seconds, status)
      integer, intent(in) :: events
      real(dp), intent(out) :: drift, seconds
      integer, intent(out) :: steps
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_result) :: res
      real(dp), allocatable :: forces(:)
      real(dp) :: approach
      integer :: info
      spec%kind = "self-affine"
      spec%label = "long run"
      spec%matrix_file = ""
      spec%np = 100
      spec%pixel = 5
      spec%rms = 3
      spec%maxcont = events
      call build_problem(spec, deck, status)
      call solve(deck, "incremental", [real(dp) ::], res, status)
      if (status%code /= 0) return
      ! The accumulated end state against the oracles' dense solve of its contact set.
      allocate(forces(size(res%contact_i)))
      call exact_state(deck, love_table(deck%np), res%contact_i, res%contact_j, res%reported_load, forces, approach, &
         info)
      drift = max(abs(res%step_approach(res%nsteps) - approach)/approach, &
         maxval(abs(res%contact_force - forces))/maxval(abs(forces)))
      steps = res%nsteps
      seconds = res%wall_seconds
   end subroutine long_run_drift
end module stability_cases
