!> Periodic surfaces (`--boundary periodic`): the periodic Love kernel against a sum over
!> its images in real space, the cyclic convolution against a direct sum, and the
!> solutions against Westergaard's sinusoid, Johnson, Greenwood and Higginson's wavy
!> surface and the free half-space.
module test_periodic
   use femcod_kinds, only: dp
   use femcod_love, only: love_influence, offset_table, surface_compliance
   use femcod_love_periodic, only: periodic_love_spectrum, periodic_offset_table
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, &
      convolution_free, inverse_kernel_taps
   use femcod_random, only: random_stream, seed_stream, uniform
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings, &
      SOLVER_INCREMENTAL, SOLVER_CG, BOUNDARY_PERIODIC, solver_name
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use femcod_deck, only: read_deck
   use femcod_scene, only: initial_gaps
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_read, h5_read_string_attribute
   use femcod_status, only: STATUS_BAD_INPUT, STATUS_USAGE
   use test_support, only: scratch_path, read_text, file_exists, remove_scratch, missed_final_check_of
   use test_incremental, only: events
   use test_cg, only: rough_scene
   use oracles, only: event_path
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_periodic

   real(dp), parameter :: pi = 3.141592653589793238462643383279502884_dp

contains

   subroutine collect_periodic(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("kernel: differences equal a real-space sum over 401^2 images (NP 8, 9)", test_image_sum), &
         new_unittest("cyclic FFT convolution equals the direct periodic sum (NP 7, 8, 33)", test_cyclic), &
         new_unittest("inverse taps on the periodic grid invert its spectrum off zero frequency", test_taps), &
         new_unittest("Westergaard's sinusoid: contact widths at a/lambda = 1/6, 1/4, 1/3, full contact at p*", &
            test_westergaard), &
         new_unittest("wavy surface (JGH 1985): Hertz at small contact, 3/(2 pi) (1 - p/p*) gaps near full", &
            test_jgh), &
         new_unittest("a sphere far smaller than the cell: the free solution, shifted by the images", &
            test_small_sphere), &
         new_unittest("event path equals cg on a periodic rough cell (contacts, approach to 1e-8)", &
            test_event_path), &
         new_unittest("--plastic on a periodic cell, both solvers: capped at H, the load carried, area >= P/H", &
            test_plastic_periodic), &
         new_unittest("mean gap on a periodic cell: mean(g0) - approach (zero-mean displacements)", test_mean_gap), &
         new_unittest("--approach on the periodic cell: Westergaard's load at the closed-form approach, both; "// &
            "beyond full contact refused", &
            test_approach_westergaard), &
         new_unittest("femcod run --boundary periodic: maps on the periodic kernel, recorded; legacy refused", &
            test_run_periodic) &
         ]
   end subroutine collect_periodic

   !> K(p, q) - K(0, 0) of periodic_offset_table (computed in Fourier space) against the
   !> same difference summed in real space over the images X = NP (m, n), |m|, |n| <= R,
   !>     sum_X [I(x + X) - I(X)],
   !> with femcod_love's pixel influence I. The images beyond R add, to second order in
   !> x (the first cancels on the square),
   !>     |x|^2/4 sum_{X outside} 1/|X|^3 = |x|^2/4 * 4 sqrt(2)/((R + 1/2) NP^3),
   !> the integral of 1/r^3 outside the square of side 2R + 1 (the cells of the lattice
   !> outside); the next terms are O(|x|^4/(R^3 NP^5)). With R = 200 that leaves
   !> 7e-10 to 9e-10 (measured; 8e-11 to 1.1e-10 at R = 400, the R^-3 of the terms left
   !> out), against the kernel's largest value I(0, 0) = 3.53.
   subroutine test_image_sum(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: r = 200
      real(dp), allocatable :: k(:, :)
      real(dp) :: direct, tail, worst
      integer :: np, p, q, m, n, c
      integer, parameter :: sizes(2) = [8, 9]
      do c = 1, size(sizes)
         np = sizes(c)
         if (allocated(k)) deallocate(k)
         allocate(k(0:np - 1, 0:np - 1))
         k(:, :) = periodic_offset_table(np)
         call check(error, abs(sum(k)) < 1.0e-12_dp, "NP "//to_string(np)//": the kernel's sum is not 0: "// &
            to_string(sum(k)))
         if (allocated(error)) return
         worst = 0
         do q = 0, np/2
            do p = 0, np/2
               direct = 0
               !$omp parallel do reduction(+:direct) private(m)
               do n = -r, r
                  do m = -r, r
                     direct = direct + (love_influence(p + m*np, q + n*np) - love_influence(m*np, n*np))
                  end do
               end do
               !$omp end parallel do
               tail = real(p*p + q*q, dp)*sqrt(2.0_dp)/((r + 0.5_dp)*real(np, dp)**3)
               worst = max(worst, abs((k(p, q) - k(0, 0)) - (direct + tail)))
            end do
         end do
         call check(error, worst < 2.0e-9_dp, "NP "//to_string(np)//": largest difference "//to_string(worst))
         if (allocated(error)) return
      end do
   end subroutine test_image_sum

   !> convolution_setup(periodic) applied to random forces equals the cyclic sum
   !> sum_kl K(mod(i - k, NP), mod(j - l, NP)) F(k, l) over the periodic table, in
   !> double (1e-12 of the largest value) and float32 (1e-5).
   subroutine test_cyclic(error)
      type(error_type), allocatable, intent(out) :: error
      type(love_convolution) :: conv
      type(random_stream) :: rng
      real(dp), allocatable :: table(:, :), f(:, :), fast(:, :), fast32(:, :), direct(:, :)
      integer :: np, i, j, k, l, c
      integer, parameter :: sizes(3) = [7, 8, 33]
      call seed_stream(rng, 42)
      do c = 1, size(sizes)
         np = sizes(c)
         if (allocated(table)) deallocate(table)
         allocate(table(0:np - 1, 0:np - 1))
         table(:, :) = periodic_offset_table(np)
         allocate(f(np, np), fast(np, np), fast32(np, np), direct(np, np))
         do j = 1, np
            do i = 1, np
               call uniform(rng, f(i, j))
            end do
         end do
         direct = 0
         do l = 1, np
            do k = 1, np
               do j = 1, np
                  do i = 1, np
                     direct(i, j) = direct(i, j) + table(modulo(i - k, np), modulo(j - l, np))*f(k, l)
                  end do
               end do
            end do
         end do
         call convolution_setup(conv, table, single=.true., periodic=.true.)
         call convolution_apply(conv, f, fast)
         call convolution_apply_single(conv, f, fast32)
         call convolution_free(conv)
         call check(error, maxval(abs(fast - direct)) < 1.0e-12_dp*maxval(abs(direct)), "NP "//to_string(np)// &
            ": double differs by "//to_string(maxval(abs(fast - direct))))
         if (allocated(error)) return
         call check(error, maxval(abs(fast32 - direct)) < 1.0e-5_dp*maxval(abs(direct)), "NP "//to_string(np)// &
            ": float32 differs by "//to_string(maxval(abs(fast32 - direct))))
         if (allocated(error)) return
         deallocate(f, fast, fast32, direct)
      end do
   end subroutine test_cyclic

   !> The 13-point taps of the periodic grid against a direct DFT of the pseudo-inverse:
   !> tap(a, b) = 1/NP^2 sum over k /= 0 of cos(2 pi (a k1 + b k2)/NP) / S(k) with the
   !> spectrum S of periodic_love_spectrum (mirrored to the whole grid).
   subroutine test_taps(error)
      type(error_type), allocatable, intent(out) :: error
      type(love_convolution) :: conv
      real(dp), allocatable :: s(:, :)
      real(dp) :: taps(0:2, 0:2), expected
      logical :: ok
      integer :: np, a, b, k1, k2, c
      integer, parameter :: sizes(2) = [8, 9]
      do c = 1, size(sizes)
         np = sizes(c)
         if (allocated(s)) deallocate(s)
         allocate(s(0:np/2, 0:np/2))
         s(:, :) = periodic_love_spectrum(np)
         call convolution_setup(conv, periodic_offset_table(np), periodic=.true.)
         call inverse_kernel_taps(conv, taps, ok)
         call convolution_free(conv)
         call check(error, ok, "NP "//to_string(np)//": no taps")
         if (allocated(error)) return
         do b = 0, 2
            do a = 0, 2
               expected = 0
               do k2 = 0, np - 1
                  do k1 = 0, np - 1
                     if (k1 == 0 .and. k2 == 0) cycle
                     expected = expected + cos(2*pi*real(a*k1 + b*k2, dp)/np)/s(min(k1, np - k1), min(k2, np - k2))
                  end do
               end do
               expected = expected/real(np, dp)**2
               call check(error, abs(taps(a, b) - expected) < 1.0e-12_dp*abs(taps(0, 0)), "NP "//to_string(np)// &
                  ": tap ("//to_string(a)//", "//to_string(b)//") "//to_string(taps(a, b))//" vs "//to_string(expected))
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_taps

   !> A problem on an NP x NP cell of 1 nm pixels: the lower body elastic (E = 200 GPa,
   !> nu = 0.25, E* = 213.3 GPa) with heights z, the upper rigid and flat (modulus and
   !> contact elements 1e10 times stiffer, as mkdeck makes them).
   function elastic_on_rigid(z) result(problem)
      real(dp), intent(in) :: z(:, :)
      type(contact_problem) :: problem
      problem%label = "periodic test"
      problem%np = size(z, 1)
      problem%pixel = 1
      problem%maxcont = problem%np**2
      problem%young = [200.0_dp, 2.0e12_dp, 2.0e12_dp]
      problem%poisson = [0.25_dp, 0.25_dp, 0.25_dp]
      problem%lower = z
      allocate(problem%upper(problem%np, problem%np))
      problem%upper = 0
   end function elastic_on_rigid

   !> Westergaard (1939): the wavy surface h = h0 cos(2 pi x / lambda) on an elastic
   !> half-space pressed by a rigid flat at mean pressure p has contact half-width a with
   !>     p = p* sin^2(pi a / lambda),   p* = pi E* h0 / lambda,
   !> and full contact from p*. Here lambda = NP d along the rows (the heights vary with
   !> the column, constant down it), peak on pixel column 1. The contact width, 2 a, is
   !> counted in pixels on one row; the discrete edge lies within a pixel of the
   !> continuous one on each side, so |count d - 2 a| <= 2 d (measured: within one pixel
   !> in all, doc/solver.md). The approach A (femcod's periodic convention: the
   !> fall of the mean gap, A = h0 - mean gap) against the closed form of the mean gap of
   !> the wavy contact, A/h0 = (p/p*)(1 - ln(p/p*)) (Johnson, Contact Mechanics 1985,
   !> section 13.2): to 1e-3 (measured at NP = 128: 2e-4 at a/lambda = 1/6, 1e-5 at
   !> 1/4). Full contact: none at 0.999 p*, every pixel at 1.001 p* (the discrete
   !> threshold differs from p* by O(NP^-2), 1e-4 here).
   subroutine test_westergaard(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 128
      real(dp), parameter :: h0 = 1, widths(3) = [1.0_dp/6, 1.0_dp/4, 1.0_dp/3]
      type(contact_problem) :: problem
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp), allocatable :: z(:, :)
      real(dp) :: estar, pstar, lambda, ratio, expected
      integer :: j, k, width
      allocate(z(np, np))
      do j = 1, np
         z(:, j) = h0*cos(2*pi*(j - 1)/np)
      end do
      problem = elastic_on_rigid(z)
      lambda = np*problem%pixel
      estar = 200/(1 - 0.25_dp**2)
      pstar = pi*estar*h0/lambda
      options%solver = SOLVER_CG
      options%boundary = BOUNDARY_PERIODIC
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      options%loads = [(pstar*sin(pi*widths(k))**2*lambda**2, k = 1, size(widths)), 0.999_dp*pstar*lambda**2, &
         1.001_dp*pstar*lambda**2]
      call solve_contact(problem, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      do k = 1, size(widths)
         width = count(res%states(k)%i == 1)
         call check(error, abs(width - 2*widths(k)*np) <= 2, "a/lambda = "//to_string(widths(k))//": "// &
            to_string(width)//" pixels in contact on a row, Westergaard "//to_string(2*widths(k)*np))
         if (allocated(error)) return
         ratio = sin(pi*widths(k))**2
         expected = h0*ratio*(1 - log(ratio))
         call check(error, res%states(k)%approach, expected, rel=.true., thr=1.0e-3_dp, message="a/lambda = "// &
            to_string(widths(k))//": approach "//to_string(res%states(k)%approach)//" nm, closed form "// &
            to_string(expected))
         if (allocated(error)) return
      end do
      call check(error, res%states(4)%contacts < np**2, "full contact at 0.999 p*")
      if (allocated(error)) return
      call check(error, res%states(5)%contacts, np**2, "not full contact at 1.001 p*")
   end subroutine test_westergaard

   !> Johnson, Greenwood and Higginson (1985): the wavy surface
   !> h = h0 cos(2 pi x / lambda) cos(2 pi y / lambda) on a half-space pressed by a rigid
   !> flat. Full contact from p* = sqrt(2) pi E* h0 / lambda. At small loads each of the two
   !> peaks of a cell is a Hertz contact of radius R = lambda^2/(4 pi^2 h0) carrying
   !> p lambda^2 / 2: area fraction 2 pi a^2/lambda^2, a = (3 P R/(4 E*))^(1/3). Near full
   !> contact the two holes per cell (at the valleys) are penny cracks whose edges close
   !> smoothly: gap fraction (3/(2 pi)) (1 - p/p*) (both asymptotes derived again in
   !> doc/solver.md). Both within 5 % at NP = 128 (pixels of lambda/128; measured:
   !> 1.233 % against Hertz's 1.209 % at p = 0.002 p*, gaps 4.90 % and 2.36 % against
   !> 4.77 % and 2.39 % at 0.9 and 0.95 p*; the count has a pixel's uncertainty at each
   !> edge, and the asymptotes their own next terms).
   subroutine test_jgh(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 128
      real(dp), parameter :: h0 = 1
      type(contact_problem) :: problem
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp), allocatable :: z(:, :)
      real(dp) :: estar, pstar, lambda, r, a, hertz, gaps
      real(dp), parameter :: small(1) = [0.002_dp], near(2) = [0.9_dp, 0.95_dp]
      integer :: i, j, k
      allocate(z(np, np))
      do j = 1, np
         do i = 1, np
            z(i, j) = h0*cos(2*pi*(i - 1)/np)*cos(2*pi*(j - 1)/np)
         end do
      end do
      problem = elastic_on_rigid(z)
      lambda = np*problem%pixel
      estar = 200/(1 - 0.25_dp**2)
      pstar = sqrt(2.0_dp)*pi*estar*h0/lambda
      r = lambda**2/(4*pi**2*h0)
      options%solver = SOLVER_CG
      options%boundary = BOUNDARY_PERIODIC
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      options%loads = [small*pstar*lambda**2, near*pstar*lambda**2]
      call solve_contact(problem, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      do k = 1, size(small)
         a = (3*small(k)*pstar*lambda**2/2*r/(4*estar))**(1.0_dp/3)
         hertz = 2*pi*a**2/lambda**2
         call check(error, res%states(k)%contacts/real(np, dp)**2, hertz, rel=.true., thr=0.05_dp, &
            message="p/p* = "//to_string(small(k))//": area fraction against Hertz")
         if (allocated(error)) return
      end do
      do k = 1, size(near)
         gaps = 1 - res%states(size(small) + k)%contacts/real(np, dp)**2
         call check(error, gaps, 3/(2*pi)*(1 - near(k)), rel=.true., thr=0.05_dp, &
            message="p/p* = "//to_string(near(k))//": gap fraction against JGH")
         if (allocated(error)) return
      end do
   end subroutine test_jgh

   !> A paraboloid of radius 200 nm (pixel 1 nm) on a 128 x 128 cell at 200 nN, contact
   !> radius about 5 pixels: the periodic solution is the free one, up to the images. Near
   !> the contact the periodic kernel is the free one plus a constant D = K(0,0) - I(0,0)
   !> (the images' displacement and the zero mean), plus |r|^2/(4 NP^3) sum 1/|m|^3 =
   !> 9.03 |r|^2/(4 NP^3), 1e-4 of the kernel over the contact: the same 89 contacts, the
   !> same forces to 1e-3 of the largest (measured 1.4e-4), and the approach shifted by
   !> c P D (to 1e-3; measured 7e-5).
   subroutine test_small_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 128
      real(dp), parameter :: radius = 200, load = 200
      type(contact_problem) :: problem
      type(contact_options) :: options
      type(contact_result) :: free, periodic
      type(status_type) :: status
      real(dp), allocatable :: z(:, :), kp(:, :)
      real(dp) :: c, shift
      integer :: i, j
      allocate(z(np, np))
      do j = 1, np
         do i = 1, np
            z(i, j) = -((i - 65)**2 + (j - 65)**2)/(2*radius)
         end do
      end do
      problem = elastic_on_rigid(z)
      options%solver = SOLVER_CG
      options%cg = cg_settings()
      options%cg%tol = 1.0e-12_dp
      options%cg%max_iterations = 5000
      options%loads = [load]
      call solve_contact(problem, options, free, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      options%boundary = BOUNDARY_PERIODIC
      call solve_contact(problem, options, periodic, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      allocate(kp(0:np - 1, 0:np - 1))
      kp(:, :) = periodic_offset_table(np)
      c = surface_compliance(200.0_dp, 0.25_dp, 1.0_dp) + surface_compliance(2.0e12_dp, 0.25_dp, 1.0_dp)
      shift = c*load*(kp(0, 0) - love_influence(0, 0))
      call check(error, periodic%states(1)%contacts, free%states(1)%contacts, "contacts")
      if (allocated(error)) return
      call check(error, all(periodic%states(1)%i == free%states(1)%i .and. periodic%states(1)%j == free%states(1)%j), &
         "the same contact pixels")
      if (allocated(error)) return
      call check(error, maxval(abs(free%states(1)%force - periodic%states(1)%force)) < &
         1.0e-3_dp*maxval(free%states(1)%force), "forces differ by "// &
         to_string(maxval(abs(free%states(1)%force - periodic%states(1)%force))))
      if (allocated(error)) return
      call check(error, periodic%states(1)%approach - shift, free%states(1)%approach, rel=.true., thr=1.0e-3_dp, &
         message="approach less c P D against the free approach")
   end subroutine test_small_sphere

   !> The event-exact path and the cg solver on the same periodic rough cell (a random sum
   !> of 12 waves that fit the cell, 32 x 32), against an outside reference: the brute-
   !> force event path of test/oracles (dense LU solves of each contact set and
   !> direct-sum gaps, no part of femcod's solvers) with the periodic table, whose
   !> differences test_image_sum checks against real-space sums over 401^2 images. The
   !> event path has the oracle's events (contacts, loads within 1e-9, the bound the free
   !> surface's test_oracle_events holds); at the midpoints of five of its steps the cg
   !> solution has the same contacts and approach to 1e-8 (measured 1e-11), and the event
   !> path's final full-field check finds no penetration.
   subroutine test_event_path(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 32, waves = 12
      type(contact_problem) :: problem
      type(contact_options) :: options
      type(contact_result) :: inc, cg
      type(status_type) :: status
      type(random_stream) :: rng
      real(dp), allocatable :: z(:, :), loads(:), li(:), oracle_loads(:), table(:, :)
      integer, allocatable :: ci(:), oracle_counts(:)
      real(dp) :: amp, phase, u, worst
      integer :: i, j, w, k1, k2, k, n, m, mi, mo
      logical :: released
      call seed_stream(rng, 7)
      allocate(z(np, np))
      z = 0
      do w = 1, waves
         call uniform(rng, u)
         k1 = int(u*6) + 1
         call uniform(rng, u)
         k2 = int(u*13) - 6
         call uniform(rng, amp)
         call uniform(rng, phase)
         do j = 1, np
            do i = 1, np
               z(i, j) = z(i, j) + amp/sqrt(real(k1*k1 + k2*k2, dp))*cos(2*pi*(real(k1*(i - 1) + k2*(j - 1), dp)/np &
                  + phase))
            end do
         end do
      end do
      problem = elastic_on_rigid(z)
      problem%maxcont = 200
      options%boundary = BOUNDARY_PERIODIC
      options%solver = SOLVER_INCREMENTAL
      call solve_contact(problem, options, inc, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      allocate(li(inc%nsteps), ci(inc%nsteps), oracle_loads(problem%maxcont + 1), oracle_counts(problem%maxcont + 1))
      call events(inc, li, ci, mi)
      allocate(table(0:np - 1, 0:np - 1))
      table(:, :) = periodic_offset_table(np)
      call event_path(problem, table, 1.0e-9_dp, problem%maxcont + 1, huge(1.0_dp), oracle_loads, oracle_counts, &
         mo, released)
      ! The events before the oracle's path would need a release (it follows none).
      call check(error, mo >= 20 .and. mi >= mo, to_string(mi)//" events of the solver, "//to_string(mo)// &
         " of the oracle")
      if (allocated(error)) return
      worst = 0
      do k = 1, mo
         call check(error, ci(k), oracle_counts(k), "contacts at event "//to_string(k)//" (oracle)")
         if (allocated(error)) return
         worst = max(worst, abs(li(k) - oracle_loads(k))/oracle_loads(k))
      end do
      call check(error, worst < 1.0e-9_dp, "event loads within 1e-9 of the oracle's, worst "//to_string(worst))
      if (allocated(error)) return
      n = inc%nsteps
      m = min(5, n - 1)
      allocate(loads(m))
      do k = 1, m
         associate(s => 1 + (k*(n - 1))/(m + 1))
            loads(k) = (inc%step_load(s) + inc%step_load(s + 1))/2
         end associate
      end do
      options%loads = loads
      call solve_contact(problem, options, inc, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      options%solver = SOLVER_CG
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      call solve_contact(problem, options, cg, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, missed_final_check_of(inc), 0, "the event path's final check found penetrating pixels")
      if (allocated(error)) return
      do k = 1, m
         call check(error, cg%states(k)%contacts, inc%states(k)%contacts, "contacts at "//to_string(loads(k))//" nN")
         if (allocated(error)) return
         call check(error, cg%states(k)%approach, inc%states(k)%approach, rel=.true., thr=1.0e-8_dp, &
            message="approach at "//to_string(loads(k))//" nN")
         if (allocated(error)) return
      end do
   end subroutine test_event_path

   !> The plastic cap on the periodic cell: Westergaard's sinusoid (NP = 64) at half its
   !> full-contact pressure, whose elastic peak pressure is 2 p / sin(pi a / lambda)
   !> = 2.83 p (a/lambda = 1/4), capped at H = 1.5 p: pixels reach H, none exceeds it,
   !> the forces sum to the load (1e-12), and the contact is at least the bearing area
   !> P/(H d^2) pixels (a capped pixel carries exactly H d^2); cg and the event path (whose
   !> 64 identical rows make every event a tie of 64 pixels) agree on the contacts, the
   !> plastic pixels and the approach (1e-8).
   subroutine test_plastic_periodic(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 64
      type(contact_problem) :: problem
      type(contact_options) :: options
      type(contact_result) :: res(2)
      type(status_type) :: status
      real(dp), allocatable :: z(:, :)
      real(dp) :: pstar, mean_pressure, load
      integer :: j, solver
      allocate(z(np, np))
      do j = 1, np
         z(:, j) = cos(2*pi*(j - 1)/np)
      end do
      problem = elastic_on_rigid(z)
      pstar = pi*200/(1 - 0.25_dp**2)/np
      mean_pressure = pstar/2
      load = mean_pressure*np**2
      do solver = 1, 2
         options%solver = merge(SOLVER_CG, SOLVER_INCREMENTAL, solver == 1)
         options%boundary = BOUNDARY_PERIODIC
         options%plastic = .true.
         options%hardness = 1.5_dp*mean_pressure
         options%cg = cg_settings()
         options%cg%tol = 1.0e-10_dp
         options%loads = [load]
         call solve_contact(problem, options, res(solver), status)
         call check(error, status%code, 0, solver_name(options%solver)//": "//status%message)
         if (allocated(error)) return
         associate(st => res(solver)%states(1))
            call check(error, st%n_plastic > 0, solver_name(options%solver)//": no pixel reached H")
            if (allocated(error)) return
            call check(error, maxval(st%force) <= options%hardness*(1 + 1.0e-12_dp), solver_name(options%solver)// &
               ": a pressure above H: "//to_string(maxval(st%force)))
            if (allocated(error)) return
            call check(error, sum(st%force), load, rel=.true., thr=1.0e-12_dp, message=solver_name(options%solver)// &
               ": the forces' sum")
            if (allocated(error)) return
            call check(error, real(st%contacts, dp) >= load/options%hardness, solver_name(options%solver)//": contacts "// &
               to_string(st%contacts)//" below the bearing area "//to_string(load/options%hardness))
            if (allocated(error)) return
         end associate
      end do
      call check(error, res(2)%states(1)%contacts, res(1)%states(1)%contacts, "the two solvers' contacts")
      if (allocated(error)) return
      call check(error, res(2)%states(1)%n_plastic, res(1)%states(1)%n_plastic, "the two solvers' plastic pixels")
      if (allocated(error)) return
      call check(error, res(2)%states(1)%approach, res(1)%states(1)%approach, rel=.true., thr=1.0e-8_dp, &
         message="the two solvers' approach")
   end subroutine test_plastic_periodic

   !> The command line: `--boundary periodic` with the legacy solver is refused (exit 2,
   !> no result file); with the incremental solver on input/sphere_d1.deck (30 x 30,
   !> 1 nm) at 100 and 1000 nN the run records the boundary in /run and the summary
   !> file, and the gap map of PREFIX.h5 (made after the solve, by the cyclic FFT) equals
   !> g0 - A + c sum K(|i - k| , |j - l|) F(k, l) summed directly over the periodic table,
   !> 0 on the contacts and nowhere negative, to 1e-10 of the height range.
   subroutine test_run_periodic(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: st
      type(h5_file) :: file
      character(len=:), allocatable :: prefix, boundary
      real(dp), allocatable :: gap(:, :), pressure(:, :), table(:, :), g0(:, :), direct(:, :)
      real(dp) :: approach, c, scale
      integer :: code, np, i, j, k, l
      prefix = scratch_path("periodic-legacy")
      call remove_scratch(prefix//".h5")
      call run_femcod([string_type("run"), string_type("input/sphere_d1.deck"), string_type("--solver"), &
         string_type("legacy"), string_type("--boundary"), string_type("periodic"), string_type("-o"), &
         string_type(prefix), string_type("--quiet")], code)
      call check(error, code, 2, "--boundary periodic with the legacy solver")
      if (allocated(error)) return
      call check(error, .not. file_exists(prefix//".h5"), "a result file of a refused run")
      if (allocated(error)) return
      prefix = scratch_path("periodic-run")
      call run_femcod([string_type("run"), string_type("input/sphere_d1.deck"), string_type("--boundary"), &
         string_type("periodic"), string_type("--loads"), string_type("100,1000"), string_type("-o"), &
         string_type(prefix), string_type("--quiet"), string_type("--force")], code)
      call check(error, code, 0, "the periodic run")
      if (allocated(error)) return
      call check(error, index(read_text(prefix//".summary.json"), '"boundary": "periodic"') > 0, &
         "the summary file's boundary")
      if (allocated(error)) return
      call h5_open(prefix//".h5", file, st, STATUS_BAD_INPUT)
      call h5_read_string_attribute(file, "/run", "boundary", 16, boundary, st, STATUS_BAD_INPUT)
      call h5_read(file, "/loads/002/gap", gap, st, STATUS_BAD_INPUT)
      call h5_read(file, "/loads/002/pressure", pressure, st, STATUS_BAD_INPUT)
      call h5_close(file, st)
      call check(error, st%code, 0, st%message)
      if (allocated(error)) return
      call check(error, boundary, "periodic", "/run boundary")
      if (allocated(error)) return
      ! The approach at 1000 nN: the second field of the second row of PREFIX.loads.csv.
      block
         character(len=:), allocatable :: csv
         integer :: at, ios
         csv = read_text(prefix//".loads.csv")
         at = index(csv, new_line("a"))
         csv = csv(at + 1:)
         at = index(csv, new_line("a"))
         csv = csv(at + 1:)
         csv = csv(index(csv, ",") + 1:)
         read(csv(:index(csv, ",") - 1), *, iostat=ios) approach
         call check(error, ios, 0, "the approach in PREFIX.loads.csv")
         if (allocated(error)) return
      end block
      call read_deck("input/sphere_d1.deck", deck, st)
      np = deck%np
      allocate(table(0:np - 1, 0:np - 1), direct(np, np))
      table(:, :) = periodic_offset_table(np)
      g0 = transpose(reshape(initial_gaps(deck%lower, deck%upper), [np, np]))
      scale = maxval(g0) - minval(g0)
      c = surface_compliance(deck%young(1), deck%poisson(1), deck%pixel) + &
         surface_compliance(deck%young(2), deck%poisson(2), deck%pixel)
      do j = 1, np
         do i = 1, np
            direct(i, j) = g0(i, j) - approach
            do l = 1, np
               do k = 1, np
                  direct(i, j) = direct(i, j) + c*table(abs(i - k), abs(j - l))*pressure(k, l)*deck%pixel**2
               end do
            end do
            if (pressure(i, j) > 0) direct(i, j) = 0
         end do
      end do
      call check(error, maxval(abs(gap - direct)) < 1.0e-10_dp*scale, "the gap map differs from the direct "// &
         "periodic sum by "//to_string(maxval(abs(gap - direct))))
      if (allocated(error)) return
      call check(error, minval(gap) > -1.0e-10_dp*scale, "a negative gap: "//to_string(minval(gap)))
   end subroutine test_run_periodic

   !> Displacement control on the periodic cell: Westergaard's sinusoid (NP = 128) at the
   !> approaches the closed form A/h0 = (p/p*)(1 - ln(p/p*)) gives for p/p* = 1/4 and 1/2
   !> (a/lambda = 1/6 and 1/4). Both solvers find the mean pressure within 1e-3 of p (the
   !> approach's discretisation error at this resolution is 2e-4 and 1e-5, and
   !> dp/dA = p/(A ln(p*/p)) magnifies it by at most 1/ln 2, test_westergaard), and the
   !> two agree to 1e-7.
   subroutine test_approach_westergaard(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 128
      real(dp), parameter :: ratios(2) = [0.25_dp, 0.5_dp]
      type(contact_problem) :: problem
      type(contact_options) :: options
      type(contact_result) :: res(2)
      type(status_type) :: status
      real(dp), allocatable :: z(:, :)
      real(dp) :: pstar, lambda
      integer :: j, k, solver
      allocate(z(np, np))
      do j = 1, np
         z(:, j) = cos(2*pi*(j - 1)/np)
      end do
      problem = elastic_on_rigid(z)
      lambda = np*problem%pixel
      pstar = pi*200/(1 - 0.25_dp**2)/lambda
      do solver = 1, 2
         options = contact_options()
         options%solver = merge(SOLVER_CG, SOLVER_INCREMENTAL, solver == 1)
         options%boundary = BOUNDARY_PERIODIC
         options%loads = [real(dp) ::]
         options%approaches = ratios*(1 - log(ratios))
         options%cg = cg_settings()
         options%cg%tol = 1.0e-10_dp
         options%cg%max_iterations = 5000
         call solve_contact(problem, options, res(solver), status)
         call check(error, status%code, 0, solver_name(options%solver)//": "//status%message)
         if (allocated(error)) return
         do k = 1, size(ratios)
            call check(error, res(solver)%states(k)%load/lambda**2, ratios(k)*pstar, rel=.true., thr=1.0e-3_dp, &
               message=solver_name(options%solver)//": mean pressure at p/p* = "//to_string(ratios(k)))
            if (allocated(error)) return
         end do
      end do
      do k = 1, size(ratios)
         call check(error, res(1)%states(k)%load, res(2)%states(k)%load, rel=.true., thr=1.0e-7_dp, &
            message="the two solvers' loads at p/p* = "//to_string(ratios(k)))
         if (allocated(error)) return
      end do
      ! Full contact comes at the approach h0 = 1 nm, the mean of the gaps 1 - cos (the
      ! closed form above at p = p*); beyond it no load gives the approach: cg refuses it
      ! at once instead of iterating to its limit.
      options = contact_options()
      options%solver = SOLVER_CG
      options%boundary = BOUNDARY_PERIODIC
      options%loads = [real(dp) ::]
      options%approaches = [0.5_dp, 1.01_dp]
      call solve_contact(problem, options, res(1), status)
      call check(error, status%code == STATUS_USAGE .and. index(status%message, "full contact") > 0, &
         "approach 1.01 h0: exit "//to_string(status%code)//", "//status%message)
   end subroutine test_approach_westergaard
   !> The mean gap cg reports on a periodic cell (summary.json's mean_gap_nm, from its gap
   !> map). Reference, from the kernel's definition: the periodic Love kernel has no zero-
   !> frequency term, so the displacements have zero mean over the cell and the mean gap
   !> is mean(g0) - A exactly, g0 the initial gaps (femcod_scene, summed here) and A the
   !> approach; to 1e-9 of the height range at --tol 1e-10 (the gaps' error bound).
   subroutine test_mean_gap(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp), allocatable :: g0(:)
      integer :: k
      call rough_scene(32, 4, deck)
      options%solver = SOLVER_CG
      options%boundary = BOUNDARY_PERIODIC
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%loads = [200.0_dp, 2000.0_dp]
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      g0 = initial_gaps(deck%lower, deck%upper)
      do k = 1, 2
         call check(error, abs(res%states(k)%mean_gap - (sum(g0)/size(g0) - res%states(k)%approach)) <= &
            1.0e-9_dp*(maxval(g0) - minval(g0)), "load "//to_string(options%loads(k))//": mean gap "// &
            to_string(res%states(k)%mean_gap)//", mean(g0) - A = "//to_string(sum(g0)/size(g0) - &
            res%states(k)%approach))
         if (allocated(error)) return
      end do
   end subroutine test_mean_gap
end module test_periodic
