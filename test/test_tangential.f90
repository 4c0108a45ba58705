!> Tangential loading with Coulomb friction (solvers/femcod_tangential) and its kernel
!> (model/femcod_cerruti). The references, none of them the code under test:
!> - the Cerruti pixel integrals against a Gauss-Legendre quadrature (this file's) of the
!>   point-force solution's integrands over the pixel, and the self term against its
!>   closed form 4 ln(1 + sqrt 2) (the Love integral of the unit square at its centre);
!> - Cattaneo and Mindlin's sphere (Johnson, Contact Mechanics, 7.2): the stick radius
!>   c/a = (1 - Q/(mu P))^(1/3) and the shift 3 mu P (2 - nu)/(16 a G) [1 - (1 - Q/(mu
!>   P))^(2/3)] on a rigid paraboloid over an elastic body with nu = 0 (where their
!>   solution is exact: the slip is then along x), at three resolutions;
!> - full sliding at Q = mu P (every traction mu p) and Q -> 0 (everything sticks);
!> - a dense quadratic program with a disc per pixel, solved here by block Gauss-Seidel
!>   (each pixel's exact minimiser in turn) on a matrix built from this file's own
!>   closed form of the kernel, on a small rough surface.
module test_tangential
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings, SOLVER_CG, BOUNDARY_PERIODIC
   use femcod_solver, only: solve_contact
   use femcod_cerruti, only: cerruti_integrals, periodic_tangential_spectra
   use femcod_convolution, only: shear_transform, shear_transform_setup_periodic, shear_transform_apply, &
      shear_transform_free
   use femcod_tangential, only: tangential_request, tangential_answer, solve_tangential
   use femcod_observer, only: solver_observer
   use femcod_status, only: STATUS_INTERRUPTED
   use test_cg, only: rough_scene
   use femcod_generate, only: paraboloid_problem
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_read
   use femcod_status, only: STATUS_BAD_INPUT
   use test_support, only: scratch_path, file_exists
   use test_results, only: csv_named_column
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_tangential

   real(dp), parameter :: pi = acos(-1.0_dp)

   !> An observer that asks to stop at its third question (a stop signal, as femcod run's
   !> observer reports SIGTERM).
   type, extends(solver_observer) :: stop_soon
      integer :: asked = 0
   contains
      procedure :: stop_requested => third_time
   end type stop_soon

contains

   subroutine collect_tangential(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("Cerruti pixel integrals: quadrature of the point solution, the self term", test_integrals), &
         new_unittest("periodic Cerruti kernel: differences equal real-space image sums (NP 8, 9)", test_periodic_kernel), &
         new_unittest("Cattaneo-Mindlin: stick radius and shift at a/d = 8, 16, 32, with the order", &
            test_cattaneo_mindlin), &
         new_unittest("Q = mu P: every traction mu p; Q -> 0: every pixel sticks", test_limits), &
         new_unittest("a dense QP with disc constraints (block Gauss-Seidel) on a rough surface", test_dense), &
         new_unittest("the same on a periodic rough cell, its matrix from real-space image sums", test_dense_periodic), &
         new_unittest("femcod run --tangential/--slip: maps obey Coulomb, columns, refusals", test_command), &
         new_unittest("--tangential-tol: the residual within 10 T, the step solve_tangential makes at T", &
            test_tolerance), &
         new_unittest("a stop request ends the tangential step: STATUS_INTERRUPTED, no answer", test_stop)]
   end subroutine collect_tangential

   !> The three integrals of the unit pixel at offsets off the centre against a 32 x 32
   !> Gauss-Legendre product rule of X^2/rho^3, Y^2/rho^3, X Y/rho^3 over the pixel (the
   !> integrand is smooth there: 1e-11 at offset 1, less beyond); at the centre the sum of
   !> the first two is 4 ln(1 + sqrt 2), they are equal, and the third is 0.
   subroutine test_integrals(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: offsets(2, 6) = reshape([1, 0, 0, 1, 2, 3, 5, 1, 1, 7, 10, 9], [2, 6])
      real(dp) :: w(3), quad(3)
      integer :: k
      do k = 1, size(offsets, 2)
         w = cerruti_integrals(offsets(1, k), offsets(2, k))
         quad = quadrature(offsets(1, k), offsets(2, k))
         call check(error, maxval(abs(w - quad)) < 1.0e-10_dp*maxval(abs(quad)), "offset ("// &
            to_string(offsets(1, k))//", "//to_string(offsets(2, k))//"): "//to_string(w(1))//", "// &
            to_string(w(2))//", "//to_string(w(3))//" against "//to_string(quad(1))//", "//to_string(quad(2))// &
            ", "//to_string(quad(3)))
         if (allocated(error)) return
      end do
      w = cerruti_integrals(0, 0)
      call check(error, abs(w(1) + w(2) - 4*log(1 + sqrt(2.0_dp))) < 1.0e-14_dp .and. abs(w(1) - w(2)) < 1.0e-14_dp &
         .and. w(3) == 0, "the self term: "//to_string(w(1))//", "//to_string(w(2))//", "//to_string(w(3)))
   end subroutine test_integrals

   !> The periodic cell's tangential kernel (femcod_cerruti's spectra from the alias sums
   !> of femcod_love_periodic, applied by the periodic shear transform to a unit force at
   !> pixel (1, 1), along x and along y) against the free pixel integrals summed in real
   !> space over the images NP (m, n), |m|, |n| <= R: the differences T(p, q) - T(0, 0)
   !> (the mean is a convention), the sums at R = 60, 120 and 240 extrapolated to R ->
   !> infinity as the tail falls (a/R from the second order of the images' Taylor series,
   !> b/R^2 from the lattice's edge: measured, one extrapolation left 1.7e-6 and 4.3e-7 at
   !> R = 60/120 and 120/240), to 1e-8 of the self term. One elastic body (E = 200 GPa,
   !> nu = 0.3) and a rigid one.
   subroutine test_periodic_kernel(error)
      type(error_type), allocatable, intent(out) :: error
      type(shear_transform) :: op
      real(dp), allocatable :: xx(:, :), yy(:, :), xy(:, :), fx(:, :), fy(:, :), ux(:, :), uy(:, :), vx(:, :), vy(:, :)
      real(dp) :: worst, direct(3), self, scale
      integer :: np, p, q, c
      integer, parameter :: sizes(2) = [8, 9]
      real(dp), parameter :: young(2) = [200.0_dp, 2.0e12_dp], poisson(2) = [0.3_dp, 0.3_dp]
      do c = 1, size(sizes)
         np = sizes(c)
         allocate(xx(np/2 + 1, np), yy(np/2 + 1, np), xy(np/2 + 1, np), fx(np, np), fy(np, np), ux(np, np), &
            uy(np, np), vx(np, np), vy(np, np))
         call periodic_tangential_spectra(np, 1.0_dp, young, poisson, xx, yy, xy)
         call shear_transform_setup_periodic(op, xx, yy, xy)
         fx = 0
         fy = 0
         fx(1, 1) = 1
         call shear_transform_apply(op, fx, fy, ux, uy)
         fx(1, 1) = 0
         fy(1, 1) = 1
         call shear_transform_apply(op, fx, fy, vx, vy)
         call shear_transform_free(op)
         scale = (1 + poisson(1))/(pi*young(1))
         self = scale*sum(cerruti_integrals(0, 0)*[1.0_dp, 1 - poisson(1), 0.0_dp])
         worst = 0
         do q = 0, np/2
            do p = 0, np/2
               ! Richardson in 1/R to second order: the tail a/R + b/R^2 cancels.
               direct = scale*(8*image_sum(p, q, 240) - 6*image_sum(p, q, 120) + image_sum(p, q, 60))/3
               worst = max(worst, abs((ux(p + 1, q + 1) - ux(1, 1)) - direct(1)), &
                  abs((vy(p + 1, q + 1) - vy(1, 1)) - direct(2)), abs(uy(p + 1, q + 1) - direct(3)), &
                  abs(vx(p + 1, q + 1) - direct(3)))
            end do
         end do
         call check(error, worst < 1.0e-8_dp*self, "NP "//to_string(np)//": largest difference "// &
            to_string(worst/self)//" of the self term")
         if (allocated(error)) return
         deallocate(xx, yy, xy, fx, fy, ux, uy, vx, vy)
      end do
   contains
      !> sum over |m|, |n| <= r of [K(p + m NP, q + n NP) - K(m NP, n NP)] for the xx, yy
      !> and xy combinations of the pixel integrals (the elastic body's; the rigid one's
      !> share is below the tolerance), without the factor (1 + nu)/(pi E).
      function image_sum(p, q, r) result(total)
         integer, intent(in) :: p, q, r
         real(dp) :: total(3), w(3), w0(3)
         integer :: m, n
         total = 0
         !$omp parallel do private(m, w, w0) reduction(+:total)
         do n = -r, r
            do m = -r, r
               w = cerruti_integrals(p + m*np, q + n*np)
               w0 = cerruti_integrals(m*np, n*np)
               w = w - w0
               total = total + [w(1) + (1 - poisson(1))*w(2), w(2) + (1 - poisson(1))*w(1), poisson(1)*w(3)]
            end do
         end do
         !$omp end parallel do
      end function image_sum
   end subroutine test_periodic_kernel

   !> The Gauss-Legendre product rule (32 nodes per side, by Newton's method on the
   !> Legendre polynomial) of the three integrands over the unit pixel at (p rows, q
   !> columns): X along the columns, Y against the rows (the centre at x = q, y = -p).
   function quadrature(p, q) result(v)
      integer, intent(in) :: p, q
      real(dp) :: v(3)
      integer, parameter :: n = 32
      real(dp) :: x(n), wt(n), xx, yy, r
      integer :: a, b
      call gauss_legendre(n, x, wt)
      v = 0
      do a = 1, n
         do b = 1, n
            xx = q + x(a)/2
            yy = -p + x(b)/2
            r = sqrt(xx*xx + yy*yy)
            v = v + wt(a)*wt(b)/4*[xx*xx, yy*yy, xx*yy]/r**3
         end do
      end do
   end function quadrature

   !> Nodes and weights of Gauss-Legendre on [-1, 1].
   subroutine gauss_legendre(n, x, w)
      integer, intent(in) :: n
      real(dp), intent(out) :: x(n), w(n)
      real(dp) :: z, p0, p1, p2, dp1
      integer :: i, k, it
      do i = 1, n
         z = cos(pi*(i - 0.25_dp)/(n + 0.5_dp))
         do it = 1, 100
            p0 = 1
            p1 = z
            do k = 2, n
               p2 = ((2*k - 1)*z*p1 - (k - 1)*p0)/k
               p0 = p1
               p1 = p2
            end do
            dp1 = n*(z*p1 - p0)/(z*z - 1)
            z = z - p1/dp1
            if (abs(p1/dp1) < 1.0e-16_dp) exit
         end do
         x(i) = z
         w(i) = 2/((1 - z*z)*dp1**2)
      end do
   end subroutine gauss_legendre

   !> A rigid paraboloid (R = 1000 nm) over an elastic body (E = 200 GPa, nu = 0) at the
   !> Hertz load of a = 24 nm, solved by cg (tol 1e-10), pixels of `pixel` nm.
   subroutine hertz_state(pixel, deck, res, error)
      real(dp), intent(in) :: pixel
      type(contact_problem), intent(out) :: deck
      type(contact_result), intent(out) :: res
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      type(status_type) :: status
      real(dp), parameter :: radius = 1000, a = 24
      ! femcod_generate's paraboloid: the rigid upper body, an elastic flat with nu = 0.
      deck = paraboloid_problem(2*nint(1.5_dp*a/pixel) + 1, pixel, radius, 200.0_dp)
      options%solver = SOLVER_CG
      options%loads = [4*200*a**3/(3*radius)]
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0, status%message)
   end subroutine hertz_state

   !> Cattaneo-Mindlin at Q = mu P/2 (mu = 0.3): the stick radius from the stick area
   !> (c = sqrt(A_stick/pi)) and the shift against the closed forms (module header) with
   !> Hertz's a. Pixels of a/8, a/16, a/32. Measured: the shift's error 1.1e-3, 1.5e-4,
   !> 1.3e-5 (order 3.5 between the finer two); the stick radius, a count of whole pixels,
   !> 4.0 %, 0.23 %, 0.65 % (0.25, 0.03, 0.17 pixels: the lattice's scatter, no order).
   !> Required: the shift's error falls at each halving and is below 1e-4 at a/32; the
   !> stick radius is within half a pixel at every resolution.
   subroutine test_cattaneo_mindlin(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_result) :: res
      type(tangential_request) :: request
      type(tangential_answer) :: answer
      type(status_type) :: status
      real(dp), parameter :: a = 24, mu = 0.3_dp, ratio = 0.5_dp
      real(dp) :: load, shift, stick_radius, errors(2, 3), g
      integer :: level
      load = 4*200*a**3/(3*1000)
      g = 200/2.0_dp
      shift = 3*mu*load*2/(16*a*g)*(1 - (1 - ratio)**(2.0_dp/3))
      stick_radius = a*(1 - ratio)**(1.0_dp/3)
      do level = 1, 3
         call hertz_state(a/2.0_dp**(level + 2), deck, res, error)
         if (allocated(error)) return
         request%mu = mu
         request%load = ratio*mu*res%states(1)%load
         request%tol = 1.0e-9_dp
         associate(s => res%states(1))
            call solve_tangential(deck, s%i, s%j, s%force, request, answer, status)
         end associate
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         errors(1, level) = abs(answer%shift(1) - shift)/shift
         errors(2, level) = abs(sqrt(count(answer%stick)*deck%pixel**2/pi) - stick_radius)/stick_radius
         write(*, '(a)') "           a/d = "//to_string(nint(a/deck%pixel))//": shift "//to_string(answer%shift(1))// &
            " nm (Mindlin "//to_string(shift)//"), stick radius "// &
            to_string(sqrt(count(answer%stick)*deck%pixel**2/pi))//" nm (Cattaneo "//to_string(stick_radius)// &
            "), "//to_string(answer%iterations)//" iterations, residual "//to_string(answer%residual)
      end do
      write(*, '(a)') "           order of the shift's error: "//to_string(log(errors(1, 2)/errors(1, 3))/log(2.0_dp))// &
         ", of the stick radius': "//to_string(log(errors(2, 2)/errors(2, 3))/log(2.0_dp))
      call check(error, errors(1, 2) < errors(1, 1) .and. errors(1, 3) < errors(1, 2) .and. errors(1, 3) < 1.0e-4_dp, &
         "the shift's error falls with the pixel: "//to_string(errors(1, 1))//", "//to_string(errors(1, 2))//", "// &
         to_string(errors(1, 3)))
      if (allocated(error)) return
      call check(error, all(errors(2, :)*stick_radius < 0.5_dp*a/2.0_dp**[3, 4, 5]), "the stick radius within half "// &
         "a pixel: relative errors "//to_string(errors(2, 1))//", "//to_string(errors(2, 2))//", "// &
         to_string(errors(2, 3)))
   end subroutine test_cattaneo_mindlin

   !> At Q = mu P every pixel carries mu f along x; at Q = 1e-6 mu P every pixel sticks.
   subroutine test_limits(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_result) :: res
      type(tangential_request) :: request
      type(tangential_answer) :: answer
      type(status_type) :: status
      call hertz_state(3.0_dp, deck, res, error)
      if (allocated(error)) return
      request%mu = 0.4_dp
      associate(s => res%states(1))
         request%load = request%mu*sum(s%force)
         call solve_tangential(deck, s%i, s%j, s%force, request, answer, status)
         call check(error, answer%sliding .and. all(abs(answer%tx - request%mu*s%force) <= 1.0e-15_dp*request%load) &
            .and. all(answer%ty == 0) .and. .not. any(answer%stick), "Q = mu P: tractions mu p along x")
         if (allocated(error)) return
         request%load = 1.0e-6_dp*request%mu*sum(s%force)
         call solve_tangential(deck, s%i, s%j, s%force, request, answer, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         call check(error, all(answer%stick), "Q -> 0: "//to_string(count(answer%stick))//" of "// &
            to_string(size(answer%stick))//" pixels stick")
      end associate
   end subroutine test_limits

   !> A rough surface (16^2, self-affine, 10 nm pixels) at 30000 nN; the shift S = 0.08 nm
   !> along x with mu = 0.2. The reference: the tangential compliance matrix of the
   !> contacts built from this file's kernel (the primitives Y asinh(X/|Y|), X asinh(Y/|X|),
   !> -rho at the corners; E = 200 GPa, nu = 0.25 elastic lower, the rigid upper's share
   !> included), and min 1/2 t.A t - S sum t_x over |t_k| <= mu f_k by block Gauss-
   !> Seidel: each pixel in turn minimises over its disc with the others fixed, the
   !> projection of its unconstrained minimiser (A's 2 x 2 diagonal blocks are multiples
   !> of the identity). Agreement of every force to 1e-7 of the largest.
   subroutine test_dense(error)
      type(error_type), allocatable, intent(out) :: error
      call dense_case(error, .false.)
   end subroutine test_dense

   !> test_dense on a periodic 12^2 cell (seed 4, 24000 nN, S = 0.08 nm), the matrix from
   !> the periodic table of the pixel integrals summed over the images in real space (this
   !> file's closed form, R = 30, 60, 120 extrapolated, and the zero-mean convention: the
   !> table's sum over the cell is 0), not from the code's Fourier-space kernel.
   subroutine test_dense_periodic(error)
      type(error_type), allocatable, intent(out) :: error
      call dense_case(error, .true.)
   end subroutine test_dense_periodic

   subroutine dense_case(error, periodic)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: periodic
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(tangential_request) :: request
      type(tangential_answer) :: answer
      type(status_type) :: status
      real(dp), allocatable :: m(:, :), t(:), b(:), rhs(:)
      real(dp) :: w(2), r, biggest, tol
      integer :: n, k, sweep
      call rough_scene(merge(12, 16, periodic), 4, deck)
      options%solver = SOLVER_CG
      options%loads = [merge(24000.0_dp, 30000.0_dp, periodic)]
      if (periodic) options%boundary = BOUNDARY_PERIODIC
      options%cg = cg_settings()
      options%cg%tol = 1.0e-12_dp
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      request%mu = 0.2_dp
      request%by_slip = .true.
      request%slip = 0.08_dp
      request%tol = 1.0e-11_dp
      request%periodic = periodic
      associate(s => res%states(1))
         n = size(s%i)
         call solve_tangential(deck, s%i, s%j, s%force, request, answer, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         m = dense_matrix(deck, s%i, s%j, periodic)
         b = request%mu*s%force
      end associate
      allocate(t(2*n), rhs(2*n))
      t = 0
      rhs = 0
      rhs(1:2*n:2) = request%slip
      do sweep = 1, 20000
         biggest = 0
         do k = 1, n
            ! The pixel's unconstrained minimiser given the others, then its disc.
            w = t(2*k - 1:2*k) + (rhs(2*k - 1:2*k) - matmul(m(2*k - 1:2*k, :), t))/m(2*k - 1, 2*k - 1)
            r = norm2(w)
            if (r > b(k)) w = w*b(k)/r
            biggest = max(biggest, maxval(abs(w - t(2*k - 1:2*k))))
            t(2*k - 1:2*k) = w
         end do
         if (biggest < 1.0e-15_dp*maxval(b)) exit
      end do
      ! The periodic reference's table is good to about 1e-8 of the self term (its image
      ! sums' extrapolation), which the QP's conditioning amplifies: 1e-6 there (1.1e-7
      ! measured); the free one's is exact to round-off (1.1e-11 measured).
      tol = merge(1.0e-6_dp, 1.0e-7_dp, periodic)
      call check(error, maxval(abs(t(1:2*n:2) - answer%tx)) <= tol*maxval(abs(t)) .and. &
         maxval(abs(t(2:2*n:2) - answer%ty)) <= tol*maxval(abs(t)), "forces against the dense QP: "// &
         to_string(maxval(abs(t(1:2*n:2) - answer%tx)))//", "//to_string(maxval(abs(t(2:2*n:2) - answer%ty)))// &
         " nN of "//to_string(maxval(abs(t)))//" ("//to_string(n)//" contacts, "//to_string(count(answer%stick))// &
         " sticking, "//to_string(sweep)//" sweeps)")
      if (allocated(error)) return
      write(*, '(a)') "           dense QP"//trim(merge(" (periodic)", "           ", periodic))//": "//to_string(n)// &
         " contacts, "//to_string(count(answer%stick))// &
         " stick, largest force difference "//to_string(maxval(abs(t(1:2*n:2) - answer%tx)))//" nN of "// &
         to_string(maxval(abs(t)))//", "//to_string(answer%iterations)//" iterations"
      call check(error, count(answer%stick) > 0 .and. count(answer%stick) < n, "partial slip: "// &
         to_string(count(answer%stick))//" of "//to_string(n)//" stick")
   end subroutine dense_case

   !> The 2n x 2n compliance (nm/nN) between the contacts, (x, y) of each pixel in turn,
   !> from this file's closed form of the pixel integrals: directly on the free surface;
   !> on a periodic cell from the cell's table (periodic_table).
   function dense_matrix(deck, ci, cj, periodic) result(m)
      type(contact_problem), intent(in) :: deck
      integer, intent(in) :: ci(:), cj(:)
      logical, intent(in) :: periodic
      real(dp), allocatable :: m(:, :), table(:, :, :)
      real(dp) :: w(3), c, nu
      integer :: k, l, body
      allocate(m(2*size(ci), 2*size(ci)))
      m = 0
      if (periodic) then
         allocate(table(3, 0:deck%np - 1, 0:deck%np - 1))
         table(:, :, :) = periodic_table(deck%np)
      end if
      do body = 1, 2
         nu = deck%poisson(body)
         c = (1 + nu)/(pi*deck%young(body)*deck%pixel)
         do l = 1, size(ci)
            do k = 1, size(ci)
               if (periodic) then
                  w = table(:, modulo(ci(k) - ci(l), deck%np), modulo(cj(k) - cj(l), deck%np))
               else
                  ! x along the columns, y against the rows.
                  w = own_integrals(real(cj(k) - cj(l), dp), real(ci(l) - ci(k), dp))
               end if
               m(2*k - 1, 2*l - 1) = m(2*k - 1, 2*l - 1) + c*(w(1) + (1 - nu)*w(2))
               m(2*k, 2*l) = m(2*k, 2*l) + c*(w(2) + (1 - nu)*w(1))
               m(2*k - 1, 2*l) = m(2*k - 1, 2*l) + c*nu*w(3)
               m(2*k, 2*l - 1) = m(2*k, 2*l - 1) + c*nu*w(3)
            end do
         end do
      end do
   end function dense_matrix

   !> The three pixel integrals on a periodic cell of np pixels, at row offsets p and
   !> column offsets q (0 .. np-1): the differences from offset (0, 0) summed over the
   !> images |m|, |n| <= R at R = 30, 60, 120 and extrapolated in 1/R to second order,
   !> then shifted to a zero sum over the cell.
   function periodic_table(np) result(table)
      integer, intent(in) :: np
      real(dp), allocatable :: table(:, :, :)
      real(dp) :: mean(3)
      integer :: p, q, k
      allocate(table(3, 0:np - 1, 0:np - 1))
      do q = 0, np - 1
         do p = 0, np - 1
            table(:, p, q) = (8*differences(p, q, 120) - 6*differences(p, q, 60) + differences(p, q, 30))/3
         end do
      end do
      do k = 1, 3
         mean(k) = sum(table(k, :, :))/np**2
         table(k, :, :) = table(k, :, :) - mean(k)
      end do
   contains
      function differences(p, q, r) result(total)
         integer, intent(in) :: p, q, r
         real(dp) :: total(3)
         integer :: m, n
         total = 0
         !$omp parallel do private(m) reduction(+:total)
         do n = -r, r
            do m = -r, r
               total = total + own_integrals(real(q + n*np, dp), real(-(p + m*np), dp)) - &
                  own_integrals(real(n*np, dp), real(-m*np, dp))
            end do
         end do
         !$omp end parallel do
      end function differences
   end function periodic_table

   !> int X^2/rho^3, int Y^2/rho^3, int X Y/rho^3 over the unit pixel at (x, y): this
   !> file's own closed form, the primitives at the four corners.
   pure function own_integrals(x, y) result(v)
      real(dp), intent(in) :: x, y
      real(dp) :: v(3)
      real(dp) :: sx(2), sy(2)
      integer :: a, b
      sx = [x - 0.5_dp, x + 0.5_dp]
      sy = [y - 0.5_dp, y + 0.5_dp]
      v = 0
      do a = 1, 2
         do b = 1, 2
            v = v + (-1)**(a + b)*[prim_xx(sx(a), sy(b)), prim_xx(sy(b), sx(a)), -sqrt(sx(a)**2 + sy(b)**2)]
         end do
      end do
   end function own_integrals

   !> Y ln(X + rho) by its asinh form (the term Y ln|Y| cancels over the corners).
   pure real(dp) function prim_xx(xx, yy)
      real(dp), intent(in) :: xx, yy
      prim_xx = 0
      if (yy /= 0) prim_xx = yy*log((xx + sqrt(xx*xx + yy*yy))/abs(yy))
   end function prim_xx

   !> `femcod run` on the 0.5 nm sphere deck (input/sphere_d05.deck) at 1000 and 5000 nN
   !> with mu = 0.3: under --tangential 100 the maps in PREFIX.h5 obey what Coulomb's law
   !> says (this test's reading of them): sum tau_x d^2 = Q, |tau| <= mu p everywhere and
   !> = mu p where the stick map is 0 and the slip map 1, stick + slip = the contact map
   !> (p > 0); loads.csv's tangential force is Q and its stick count the stick map's.
   !> Under --slip 0.05 the shift column is 0.05. Refused with exit 2 and no output:
   !> --friction alone, --tangential without --friction, both --tangential and --slip, a
   !> negative or zero friction coefficient, adhesion.
   subroutine test_command(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix
      type(h5_file) :: file
      type(status_type) :: st
      real(dp), allocatable :: p(:, :), tx(:, :), ty(:, :), stick(:, :), slip(:, :), column(:)
      character(len=24) :: refused(5, 8)
      integer :: code, k, n
      prefix = scratch_path("tangential_run")
      call run_femcod([string_type("run"), string_type("input/sphere_d05.deck"), string_type("--solver"), &
         string_type("cg"), string_type("--loads"), string_type("1000,5000"), string_type("--tangential"), &
         string_type("100"), string_type("--friction"), string_type("0.3"), string_type("-o"), string_type(prefix), &
         string_type("--quiet"), string_type("--force")], code)
      call check(error, code, 0, "the run")
      if (allocated(error)) return
      call h5_open(prefix//".h5", file, st, STATUS_BAD_INPUT)
      do k = 1, 2
         call h5_read(file, "/loads/00"//to_string(k)//"/pressure", p, st, STATUS_BAD_INPUT)
         call h5_read(file, "/loads/00"//to_string(k)//"/shear_x", tx, st, STATUS_BAD_INPUT)
         call h5_read(file, "/loads/00"//to_string(k)//"/shear_y", ty, st, STATUS_BAD_INPUT)
         call h5_read(file, "/loads/00"//to_string(k)//"/stick", stick, st, STATUS_BAD_INPUT)
         call h5_read(file, "/loads/00"//to_string(k)//"/slip", slip, st, STATUS_BAD_INPUT)
         call check(error, abs(sum(tx)*0.25_dp - 100) <= 1.0e-10_dp*100 .and. all(sqrt(tx**2 + ty**2) <= &
            0.3_dp*p*(1 + 1.0e-12_dp)), "load "//to_string(k)//": sum tau_x d^2 = Q, |tau| <= mu p")
         if (allocated(error)) exit
         call check(error, all((stick + slip == 1) .eqv. (p > 0)) .and. all(abs(pack(sqrt(tx**2 + ty**2), &
            slip == 1) - pack(0.3_dp*p, slip == 1)) <= 1.0e-12_dp*maxval(p)), "load "//to_string(k)// &
            ": stick + slip = contact, |tau| = mu p where it slips")
         if (allocated(error)) exit
         n = nint(sum(stick))
         call check(error, n > 0 .and. n < count(p > 0), "partial slip at load "//to_string(k))
         if (allocated(error)) exit
         column = csv_named_column(prefix//".loads.csv", "stick_contacts")
         call check(error, nint(column(k)), n, "stick_contacts of load "//to_string(k))
         if (allocated(error)) exit
      end do
      call h5_close(file, st)
      if (allocated(error)) return
      column = csv_named_column(prefix//".loads.csv", "tangential_force_nN")
      call check(error, all(abs(column - 100) <= 1.0e-10_dp*100), "tangential_force_nN = Q")
      if (allocated(error)) return
      call run_femcod([string_type("run"), string_type("input/sphere_d05.deck"), string_type("--loads"), &
         string_type("1000"), string_type("--slip"), string_type("0.05"), string_type("--friction"), &
         string_type("0.3"), string_type("-o"), string_type(prefix), string_type("--quiet"), string_type("--force")], &
         code)
      call check(error, code, 0, "the --slip run")
      if (allocated(error)) return
      column = csv_named_column(prefix//".loads.csv", "tangential_shift_nm")
      call check(error, column(1), 0.05_dp, "tangential_shift_nm = S")
      if (allocated(error)) return
      refused(:, 1) = [character(len=24) :: "--friction", "0.3", "", "", ""]
      refused(:, 2) = [character(len=24) :: "--tangential", "10", "", "", ""]
      refused(:, 3) = [character(len=24) :: "--tangential", "10", "--slip", "0.1", "--friction"]
      refused(:, 4) = [character(len=24) :: "--tangential", "10", "--friction", "-1", ""]
      refused(:, 5) = [character(len=24) :: "--tangential", "10", "--friction", "0.3", "--adhesion"]
      refused(:, 6) = [character(len=24) :: "--slip", "0.1", "--friction", "0", ""]
      refused(:, 7) = [character(len=24) :: "--tangential-tol", "1e-9", "", "", ""]
      refused(:, 8) = [character(len=24) :: "--tangential", "10", "--friction", "0.3", "--tangential-tol"]
      do k = 1, size(refused, 2)
         prefix = scratch_path("tangential_refused"//to_string(k))
         call run_femcod([string_type("run"), string_type("input/sphere_d2.deck"), string_type("--solver"), &
            string_type("cg"), string_type("--approach"), string_type("1"), string_type("-o"), string_type(prefix), &
            string_type("--quiet"), (string_type(trim(refused(n, k))), n = 1, count(refused(:, k) /= "")), &
            extra(k)], code)
         call check(error, code == 2 .and. .not. file_exists(prefix//".h5"), "refused with exit 2, nothing "// &
            "written: "//trim(refused(1, k))//" "//trim(refused(2, k))//" "//trim(refused(3, k))//" "// &
            trim(refused(4, k))//" "//trim(refused(5, k))//" (exit "//to_string(code)//")")
         if (allocated(error)) return
      end do
   contains
      !> The value of the last option of case k (its own words).
      function extra(k) result(words)
         integer, intent(in) :: k
         type(string_type), allocatable :: words(:)
         select case (k)
         case (3)
            allocate(words(1))
            words(1)%s = "0.3"
         case (5)
            allocate(words(5))
            words(1)%s = "dugdale"
            words(2)%s = "--work"
            words(3)%s = "0.1"
            words(4)%s = "--range"
            words(5)%s = "1"
         case (8)
            allocate(words(1))
            words(1)%s = "1"
         case default
            allocate(words(0))
         end select
      end function extra
   end subroutine test_command
   !> --tangential-tol T (contact_options%tangential_tol, read by tangential_request_of):
   !> the step iterates until its gradient mapping is below T of the shift and accepts a
   !> residual (the largest violation of stick and slip over the shift) up to 10 T. On the
   !> Hertz state at a/d = 8 under Q = mu P/2 through solve_contact at T = 1e-4 and 1e-12:
   !> each residual within 10 T, more iterations at the smaller T, and at 1e-12 the answer
   !> of solve_tangential asked for that tolerance directly, bit for bit.
   subroutine test_tolerance(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_result) :: res, loose, tight
      type(contact_options) :: options
      type(tangential_request) :: request
      type(tangential_answer) :: answer
      type(status_type) :: status
      call hertz_state(3.0_dp, deck, res, error)
      if (allocated(error)) return
      options%solver = SOLVER_CG
      options%loads = res%states(1:1)%load
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      options%tangential = .true.
      options%friction = 0.3_dp
      options%tangential_load = 0.5_dp*options%friction*res%states(1)%load
      options%tangential_tol = 1.0e-4_dp
      call solve_contact(deck, options, loose, status)
      options%tangential_tol = 1.0e-12_dp
      if (status%code == 0) call solve_contact(deck, options, tight, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, loose%states(1)%tangential_residual <= 1.0e-3_dp .and. &
         tight%states(1)%tangential_residual <= 1.0e-11_dp .and. &
         tight%states(1)%tangential_iterations > loose%states(1)%tangential_iterations, "residuals "// &
         to_string(loose%states(1)%tangential_residual)//" at 1e-4 ("//to_string(loose%states(1)%tangential_iterations)// &
         " iterations), "//to_string(tight%states(1)%tangential_residual)//" at 1e-12 ("// &
         to_string(tight%states(1)%tangential_iterations)//")")
      if (allocated(error)) return
      request%mu = options%friction
      request%load = options%tangential_load
      request%tol = 1.0e-12_dp
      associate(s => tight%states(1))
         call solve_tangential(deck, s%i, s%j, s%force, request, answer, status)
         call check(error, status%code == 0 .and. all(answer%tx == s%shear_x) .and. all(answer%ty == s%shear_y) .and. &
            answer%iterations == s%tangential_iterations, "the run's step is solve_tangential's at T = 1e-12")
      end associate
   end subroutine test_tolerance

   logical function third_time(self)
      class(stop_soon), intent(inout) :: self
      self%asked = self%asked + 1
      third_time = self%asked >= 3
   end function third_time

   !> The Hertz state at a/d = 8 with Q = mu P/2 takes about 100 iterations; the observer
   !> is asked every 10, and asks to stop at its third question: the step ends with
   !> STATUS_INTERRUPTED (femcod run's exit 128 + N) after 30 iterations, the question
   !> asked three times.
   subroutine test_stop(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_result) :: res
      type(tangential_request) :: request
      type(tangential_answer) :: answer
      type(status_type) :: status
      type(stop_soon) :: observer
      call hertz_state(3.0_dp, deck, res, error)
      if (allocated(error)) return
      request%mu = 0.3_dp
      associate(s => res%states(1))
         request%load = 0.5_dp*request%mu*sum(s%force)
         call solve_tangential(deck, s%i, s%j, s%force, request, answer, status, observer)
      end associate
      call check(error, status%code == STATUS_INTERRUPTED .and. observer%asked == 3 .and. &
         index(status%message, "stopped after 30 iterations") > 0, "status "//to_string(status%code)//": "// &
         status%message//" (asked "//to_string(observer%asked)//" times)")
   end subroutine test_stop
end module test_tangential
