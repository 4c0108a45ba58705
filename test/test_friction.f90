!> Friction from the contact pressures (model/femcod_shear_model, issue 37's first route):
!> F_t = sum over the contact pixels of min(tau0 + alpha p, k) d^2. Each check names the
!> reference it compares with, none of which is the code's own sum:
!> - tau0 = 0: F_t = alpha F, from the equilibrium of the contact forces with the load
!>   (sum f_i = F), so mu = alpha to the round-off of that sum;
!> - alpha = 0: F_t = tau0 times the contact area (contacts x d^2);
!> - a Hertz paraboloid: the closed-form integral of tau over Hertz's pressure
!>   p0 sqrt(1 - r^2/a^2), capped and not, within the discretisation error, which falls
!>   as the pixel does (measured at three resolutions);
!> - rough surfaces under the plastic cap: Bowden and Tabor's bound mu >= alpha + tau0/H
!>   (every contact pixel's pressure is at most H, so the area is at least F/H), and mu
!>   falling with the load as the area grows more slowly than the load.
module test_friction
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings, SOLVER_INCREMENTAL, SOLVER_LEGACY, SOLVER_CG, &
      solver_name
   use femcod_solver, only: solve_contact
   use test_cg, only: rough_scene
   use femcod_generate, only: paraboloid_problem
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_read, h5_exists
   use femcod_status, only: STATUS_BAD_INPUT
   use test_support, only: scratch_path, read_text, contains_text, file_exists, condition_of
   use test_results, only: csv_column, csv_named_column
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_friction

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_friction(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("tau0 = 0: mu = alpha at every step and state, every solver", test_slope_only), &
         new_unittest("alpha = 0: F_t = tau0 times the contact area, every solver", test_strength_only), &
         new_unittest("Hertz: F_t against the closed-form integral, capped and not, 3 resolutions", test_hertz), &
         new_unittest("rough, plastic: mu >= alpha + tau0/H and falls with the load", test_bowden_tabor), &
         new_unittest("the shear model leaves the normal answer as it is", test_no_solve), &
         new_unittest("femcod run: the columns and datasets with the model only; F_t from the maps", test_command)]
   end subroutine collect_friction

   !> Options of solver `solver` with the shear model (tau0 GPa, alpha).
   function shear_options(solver, tau0, alpha, loads) result(options)
      integer, intent(in) :: solver
      real(dp), intent(in) :: tau0, alpha, loads(:)
      type(contact_options) :: options
      options%solver = solver
      options%loads = loads
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      options%shear = .true.
      options%shear_strength = tau0
      options%shear_slope = alpha
   end function shear_options

   !> With tau0 = 0 every pixel carries alpha p, so F_t = alpha sum f_i = alpha F: the
   !> forces balance the load. The sum of n positive forces is the load to n machine
   !> epsilons (each addition rounds once); the event solvers' load is their running
   !> total, which carries as many roundings per step. The legacy solver's forces come
   !> out of its penalty springs through a skyline factor of condition kappa (its own
   !> estimate, condition_of(res), about 3e11 here): they balance the load to kappa eps
   !> (measured 1.0e-6 of it at 900 nN).
   subroutine test_slope_only(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_result) :: res
      type(status_type) :: status
      integer :: s, k
      integer, parameter :: solvers(3) = [SOLVER_INCREMENTAL, SOLVER_LEGACY, SOLVER_CG]
      real(dp), parameter :: alpha = 0.17_dp
      real(dp) :: tol
      call rough_scene(24, 5, deck, maxcont=60)
      do s = 1, size(solvers)
         call solve_contact(deck, shear_options(solvers(s), 0.0_dp, alpha, [200.0_dp, 900.0_dp]), res, status)
         call check(error, status%code, 0, solver_name(solvers(s))//": "//status%message)
         if (allocated(error)) return
         do k = 1, res%nsteps
            tol = 4*max(res%step_contacts(k), 1)*res%nsteps*epsilon(1.0_dp) + condition_of(res)*epsilon(1.0_dp)
            call check(error, res%step_friction(k)/res%step_load(k), alpha, rel=.true., thr=tol, &
               message=solver_name(solvers(s))//", step "//to_string(k))
            if (allocated(error)) return
         end do
         do k = 1, size(res%states)
            call check(error, res%states(k)%reached, solver_name(solvers(s))//": load reached")
            if (allocated(error)) return
            tol = 4*res%states(k)%contacts*max(res%nsteps, 1)*epsilon(1.0_dp) + condition_of(res)*epsilon(1.0_dp)
            call check(error, res%states(k)%friction/res%states(k)%load, alpha, rel=.true., thr=tol, &
               message=solver_name(solvers(s))//", state "//to_string(k))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_slope_only

   !> With alpha = 0 every contact pixel carries tau0: F_t = tau0 n d^2, n the contacts.
   subroutine test_strength_only(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_result) :: res
      type(status_type) :: status
      integer :: s, k
      integer, parameter :: solvers(3) = [SOLVER_INCREMENTAL, SOLVER_LEGACY, SOLVER_CG]
      real(dp), parameter :: tau0 = 0.35_dp
      call rough_scene(24, 6, deck, maxcont=60)
      do s = 1, size(solvers)
         call solve_contact(deck, shear_options(solvers(s), tau0, 0.0_dp, [300.0_dp, 1200.0_dp]), res, status)
         call check(error, status%code, 0, solver_name(solvers(s))//": "//status%message)
         if (allocated(error)) return
         do k = 1, res%nsteps
            call check(error, res%step_friction(k), tau0*res%step_contacts(k)*deck%pixel**2, rel=.true., &
               thr=4*epsilon(1.0_dp), message=solver_name(solvers(s))//", step "//to_string(k))
            if (allocated(error)) return
         end do
         do k = 1, size(res%states)
            call check(error, res%states(k)%friction, tau0*res%states(k)%contacts*deck%pixel**2, rel=.true., &
               thr=4*epsilon(1.0_dp), message=solver_name(solvers(s))//", state "//to_string(k))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_strength_only

   !> A rigid paraboloid z = -r^2/(2R) (R = 1000 nm) on an elastic half-space (E = 200 GPa,
   !> nu = 0.25), pressed to a Hertz contact radius a = 24 nm. Hertz: P = 4 E* a^3/(3R),
   !> p(r) = p0 sqrt(1 - r^2/a^2), p0 = 3P/(2 pi a^2). The closed forms of F_t:
   !> - not capped: tau0 pi a^2 + alpha P;
   !> - capped at k (tau0 = 0, alpha p0 > k): pixels with p > pc = k/alpha carry k,
   !>   inside r_c^2 = a^2 (1 - s), s = (pc/p0)^2, so
   !>   F_t = k pi r_c^2 + alpha p0 (2 pi a^2/3) s^(3/2).
   !> The cap is the plastic one (--plastic, k = H/(3 sqrt 3)) with H = 1.5 p0, above
   !> every pressure, so no pixel is plastic and Hertz holds. Solved by cg at the Hertz
   !> load on pixels of a/8, a/16 and a/32. Measured relative errors: capped 3.5e-3,
   !> 4.2e-4, 8.6e-5 (order 3 to 2.3: the integrand is continuous); not capped 2.8e-2,
   !> 5.2e-3, 4.8e-3, which is the pixel count of the area (tau0 A): the pixels along the
   !> contact's edge fall in or out as the lattice meets the circle, an error of order
   !> d/a with scatter. Required: below the coarsest's error, and 1 % at a/32.
   subroutine test_hertz(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp), parameter :: radius = 1000, a = 24, estar = 200/(1 - 0.25_dp**2)
      real(dp) :: load, p0, k, pc, s, exact(2), errors(2, 3), pixel
      integer :: level, m
      type(contact_problem) :: scene
      load = 4*estar*a**3/(3*radius)
      p0 = 3*load/(2*pi*a**2)
      ! Not capped: tau0 = 0.2 GPa, alpha = 0.1.
      exact(1) = 0.2_dp*pi*a**2 + 0.1_dp*load
      ! Capped: alpha = 0.5, H = 1.5 p0.
      k = 1.5_dp*p0/(3*sqrt(3.0_dp))
      pc = k/0.5_dp
      s = (pc/p0)**2
      exact(2) = k*pi*a**2*(1 - s) + 0.5_dp*p0*(2*pi*a**2/3)*s**1.5_dp
      do level = 1, 3
         pixel = a/2.0_dp**(level + 2)
         do m = 1, 2
            if (m == 1) then
               options = shear_options(SOLVER_CG, 0.2_dp, 0.1_dp, [load])
            else
               options = shear_options(SOLVER_CG, 0.0_dp, 0.5_dp, [load])
               options%plastic = .true.
               options%hardness = 1.5_dp*p0
            end if
            options%cg%tol = 1.0e-9_dp
            scene = paraboloid(pixel, radius, 3*a)
            call solve_contact(scene, options, res, status)
            call check(error, status%code, 0, status%message)
            if (allocated(error)) return
            call check(error, res%states(1)%n_plastic, 0, "no pixel plastic at H = 1.5 p0")
            if (allocated(error)) return
            errors(m, level) = abs(res%states(1)%friction - exact(m))/exact(m)
            write(*, '(a)') "           Hertz, a/d = "//to_string(nint(a/pixel))//", "// &
               trim(merge("not capped", "capped    ", m == 1))//": F_t "//to_string(res%states(1)%friction)// &
               " nN, closed form "//to_string(exact(m))//", relative error "//to_string(errors(m, level))
         end do
      end do
      do m = 1, 2
         call check(error, errors(m, 3) < errors(m, 1) .and. errors(m, 3) < 0.01_dp, "F_t converges to the "// &
            "closed form: errors "//to_string(errors(m, 1))//", "//to_string(errors(m, 2))//", "// &
            to_string(errors(m, 3)))
         if (allocated(error)) return
      end do
   end subroutine test_hertz

   !> A rigid paraboloid of radius `radius` (nm) over a square of side `side` (nm) with
   !> pixels of `pixel` (nm), against an elastic flat (E = 200 GPa, nu = 0.25):
   !> femcod_generate's paraboloid_problem (its flat has nu = 0) with nu set.
   function paraboloid(pixel, radius, side) result(deck)
      real(dp), intent(in) :: pixel, radius, side
      type(contact_problem) :: deck
      deck = paraboloid_problem(2*nint(side/(2*pixel)) + 1, pixel, radius, 200.0_dp)
      deck%poisson = 0.25_dp
   end function paraboloid

   !> A rough surface (self-affine, Hurst 0.8, 48^2 pixels of 10 nm) under the plastic cap,
   !> H = 2 GPa, tau0 = 0.1 GPa, alpha = 0.05 (k = H/(3 sqrt 3) = 0.385 GPa is above
   !> tau0 + alpha H = 0.2 GPa: the cap does not bind). Bowden and Tabor: every pixel's
   !> pressure is at most H, so the contact area A >= F/H and mu = alpha + tau0 A/F >=
   !> alpha + tau0/H = 0.1. On the event path and by cg, at loads over three decades (not
   !> multiples of H d^2 = 200 nN, where a fully plastic set ties with a pixel about to
   !> touch): the bound holds at every step and state, and mu falls from the smallest
   !> load to the largest (the area grows more slowly than the load).
   subroutine test_bowden_tabor(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp), parameter :: hardness = 2, tau0 = 0.1_dp, alpha = 0.05_dp
      real(dp) :: bound, mu(4)
      integer, parameter :: solvers(2) = [SOLVER_INCREMENTAL, SOLVER_CG]
      integer :: s, k
      call rough_scene(48, 11, deck)
      bound = alpha + tau0/hardness
      do s = 1, size(solvers)
         options = shear_options(solvers(s), tau0, alpha, [1.5e2_dp, 1.5e3_dp, 1.5e4_dp, 1.5e5_dp])
         options%plastic = .true.
         options%hardness = hardness
         call solve_contact(deck, options, res, status)
         call check(error, status%code, 0, solver_name(solvers(s))//": "//status%message)
         if (allocated(error)) return
         do k = 1, res%nsteps
            call check(error, res%step_friction(k)/res%step_load(k) >= bound*(1 - 1.0e-12_dp), &
               solver_name(solvers(s))//", step "//to_string(k)//": mu "// &
               to_string(res%step_friction(k)/res%step_load(k))//" below the bound "//to_string(bound))
            if (allocated(error)) return
         end do
         mu = res%states%friction/res%states%load
         write(*, '(a)') "           "//solver_name(solvers(s))//": mu at 1.5e2..1.5e5 nN: "//to_string(mu(1))//", "// &
            to_string(mu(2))//", "//to_string(mu(3))//", "//to_string(mu(4))//" (bound "//to_string(bound)//")"
         call check(error, all(mu >= bound*(1 - 1.0e-12_dp)) .and. mu(4) < mu(1), solver_name(solvers(s))// &
            ": mu falls with the load, above the bound")
         if (allocated(error)) return
      end do
   end subroutine test_bowden_tabor

   !> The shear model is a sum over the answer: with it, every solver's loads, approaches
   !> and contacts are those without it, bit for bit.
   subroutine test_no_solve(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: with, without
      type(status_type) :: status
      integer, parameter :: solvers(3) = [SOLVER_INCREMENTAL, SOLVER_LEGACY, SOLVER_CG]
      integer :: s
      call rough_scene(24, 7, deck, maxcont=50)
      do s = 1, size(solvers)
         options = shear_options(solvers(s), 0.3_dp, 0.2_dp, [250.0_dp, 700.0_dp])
         call solve_contact(deck, options, with, status)
         options%shear = .false.
         call solve_contact(deck, options, without, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         call check(error, all(with%states%approach == without%states%approach) .and. &
            all(with%states%contacts == without%states%contacts) .and. &
            all(with%step_load(1:with%nsteps) == without%step_load(1:without%nsteps)), &
            solver_name(solvers(s))//": the answer changed with the shear model")
         if (allocated(error)) return
         call check(error, all(without%states%friction == 0) .and. all(with%states%friction > 0), &
            solver_name(solvers(s))//": friction only with the shear model")
         if (allocated(error)) return
      end do
   end subroutine test_no_solve
   !> `femcod run` on the 2 nm sphere (input/sphere_d2.deck) at 300 and 800 nN, tau0 =
   !> 0.1 GPa, alpha = 0.2: loads.csv's friction_nN equals the sum of (tau0 + alpha p) d^2
   !> over the pixels of the pressure map in PREFIX.h5 where p > 0 (this test's sum over
   !> the written map), and its coefficient the ratio to the load; the history's column
   !> is /history/friction. Without the options: no such column or dataset. With
   !> --adhesion: refused (exit 2) with no output.
   subroutine test_command(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, text
      type(h5_file) :: file
      type(status_type) :: st
      real(dp), allocatable :: pressure(:, :), ft(:), mu(:), load(:), history(:)
      real(dp) :: expected
      integer :: code, k
      prefix = scratch_path("friction_run")
      call run_femcod([string_type("run"), string_type("input/sphere_d2.deck"), string_type("--loads"), &
         string_type("300,800"), string_type("--shear-strength"), string_type("0.1"), string_type("--shear-slope"), &
         string_type("0.2"), string_type("-o"), string_type(prefix), string_type("--quiet"), string_type("--force")], &
         code)
      call check(error, code, 0, "the run")
      if (allocated(error)) return
      load = csv_named_column(prefix//".loads.csv", "load_nN")
      ft = csv_named_column(prefix//".loads.csv", "friction_nN")
      mu = csv_named_column(prefix//".loads.csv", "friction_coefficient")
      call h5_open(prefix//".h5", file, st, STATUS_BAD_INPUT)
      do k = 1, 2
         call h5_read(file, "/loads/00"//to_string(k)//"/pressure", pressure, st, STATUS_BAD_INPUT)
         expected = sum(0.1_dp + 0.2_dp*pack(pressure, pressure > 0))*2.0_dp**2
         call check(error, ft(k), expected, rel=.true., thr=1.0e-13_dp, message="F_t at "//to_string(load(k)))
         if (allocated(error)) exit
         call check(error, mu(k), ft(k)/load(k), rel=.true., thr=1.0e-15_dp, message="mu at "//to_string(load(k)))
         if (allocated(error)) exit
      end do
      call h5_read(file, "/history/friction", history, st, STATUS_BAD_INPUT)
      call h5_close(file, st)
      if (allocated(error)) return
      call check(error, st%code, 0, st%message)
      if (allocated(error)) return
      call check(error, all(history == csv_column(prefix//".history.csv", 9)), "/history/friction is the column")
      if (allocated(error)) return
      call run_femcod([string_type("run"), string_type("input/sphere_d2.deck"), string_type("--loads"), &
         string_type("300,800"), string_type("-o"), string_type(prefix), string_type("--quiet"), &
         string_type("--force")], code)
      text = read_text(prefix//".loads.csv")
      call check(error, code == 0 .and. .not. contains_text(text, "friction"), "no friction column without the model")
      if (allocated(error)) return
      call h5_open(prefix//".h5", file, st, STATUS_BAD_INPUT)
      call check(error, .not. h5_exists(file, "/history/friction"), "no /history/friction without the model")
      call h5_close(file, st)
      if (allocated(error)) return
      prefix = scratch_path("friction_adhesion")
      call run_femcod([string_type("run"), string_type("input/sphere_d2.deck"), string_type("--solver"), &
         string_type("cg"), string_type("--approach"), string_type("1"), string_type("--adhesion"), &
         string_type("dugdale"), string_type("--work"), string_type("0.1"), string_type("--range"), &
         string_type("1"), string_type("--shear-slope"), string_type("0.2"), string_type("-o"), &
         string_type(prefix), string_type("--quiet")], code)
      call check(error, code == 2 .and. .not. file_exists(prefix//".h5"), "refused with --adhesion, nothing written")
   end subroutine test_command
end module test_friction
