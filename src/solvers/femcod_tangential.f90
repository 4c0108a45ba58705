!> Tangential loading with Coulomb friction (the thesis' second route to friction, section
!> 5.2.3): after the normal problem, the contact is loaded tangentially by a force Q (nN)
!> or a rigid tangential shift S (nm), both along x (the columns), at its normal state.
!>
!> Each contact pixel i carries a tangential force t_i (nN; the traction t_i/d^2) with
!> |t_i| <= b_i = mu f_i (f_i its normal force, mu the friction coefficient): it sticks
!> (|t_i| < b_i, its surface moves with the rigid shift delta: u_i = delta) or slips
!> (|t_i| = b_i, t_i along delta - u_i, the way the surface lags behind the shift). u = A t
!> is the bodies' relative tangential displacement, A their Cerruti compliance
!> (model/femcod_cerruti, applied by FFT: model/femcod_shear_operator, one process's
!> grid or, in femcod-mpi, the ranks' slabs). These are
!> the conditions of the minimum of the complementary energy
!>     shift given (slip control):  1/2 t.A t - delta . sum t,   |t_i| <= b_i,
!>     load given (force control):  1/2 t.A t,  sum t = Q,       |t_i| <= b_i,
!> a convex program whose constraints are a disc per pixel (not a bound), whose
!> multiplier of sum t = Q is delta. It is solved by accelerated projected gradients
!> (FISTA, Beck and Teboulle 2009, with O'Donoghue and Candes' adaptive restart) with the
!> step 1/L, L A's largest eigenvalue on the contacts by power iteration (times 1.25, and
!> at most the padded operator's bound; a step that proves too long is halved): on a rough
!> 512^2 surface at 6 % contact 217 iterations instead of 987 with the padded bound, the
!> lowest frequency's of the whole grid. Under force control the projection onto {discs, sum t = Q} is t_i = P_i(z_i +
!> lambda), P_i the projection onto pixel i's disc and lambda (a 2-vector) the root of
!> sum P_i(z_i + lambda) = Q, found by Newton's method (the map is monotone); at the
!> solution delta = L lambda.
!>
!> The normal pressures stay as the normal problem left them (Goodman's approximation:
!> the coupling by the second Dundurs constant beta is left out; exact for beta = 0, one
!> material or incompressible bodies). The free half-space, or a periodic cell (the kernel
!> summed over the images, zero-mean displacements: the shift is then measured from the
!> mean surface, as the normal approach from the mean gap). Q >= mu P: gross sliding,
!> every pixel at b_i along x (the shift is then the onset's at Q = mu P, unbounded
!> beyond it).
module femcod_tangential
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED
   use femcod_observer, only: solver_observer
   use femcod_strings, only: count_text, sig_str
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: contact_options, BOUNDARY_PERIODIC
   use femcod_shear_operator, only: shear_operator, grid_shear_operator, grid_shear_setup, grid_shear_free
   use femcod_contact_result, only: state_values
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   implicit none
   private
   public :: tangential_request, tangential_answer, solve_tangential, solve_tangential_on, tangential_storage_bytes, &
      tangential_request_of, keep_tangential_answer

   !> What a tangential step asks: the friction coefficient, the load (nN) or, with
   !> `by_slip`, the rigid shift (nm), both along x; the relative residual to reach and
   !> the iterations allowed.
   type :: tangential_request
      real(dp) :: mu = 0
      logical :: by_slip = .false.
      real(dp) :: load = 0, slip = 0
      real(dp) :: tol = 1.0e-8_dp
      integer :: max_iterations = 20000
      !> The grid as one cell of a periodic surface (the kernel summed over the images;
      !> solve_tangential's operator).
      logical :: periodic = .false.
   end type tangential_request

   !> The answer on this process's contact pixels, in the order of its list; the shift,
   !> the force, the iterations and the residual are the whole grid's.
   type :: tangential_answer
      !> Tangential forces (nN) and whether each pixel sticks.
      real(dp), allocatable :: tx(:), ty(:)
      logical, allocatable :: stick(:)
      !> The rigid shift (nm, the tangential approach) and the total tangential force (nN).
      real(dp) :: shift(2) = 0, force(2) = 0
      !> Gross sliding (Q >= mu P): every pixel slips.
      logical :: sliding = .false.
      integer :: iterations = 0
      !> The largest violation of the stick and slip conditions (nm) over the shift's size.
      real(dp) :: residual = 0
   end type tangential_answer

   !> The iteration's state: this process's contact list (rows, and columns of its part),
   !> the bounds, the contacts of the whole grid, the capacity mu P, the grids the
   !> operator takes, and the contacts' displacements of the last application.
   type :: tangential_state
      integer :: n = 0, contacts = 0
      integer, allocatable :: ci(:), cj(:)
      real(dp), allocatable :: bound(:)
      real(dp) :: capacity = 0
      !> u(:, k): pixel k's displacement (nm) from the last `displace`.
      real(dp), allocatable :: u(:, :)
      real(dp), allocatable :: gx(:, :), gy(:, :), ux(:, :), uy(:, :)
   end type tangential_state

contains

   !> The tangential step a run's options ask for (--friction, --tangential or --slip,
   !> --tangential-tol, --boundary): femcod run's, femcod-mpi's and the libraries' one
   !> reading of them.
   pure function tangential_request_of(options) result(request)
      type(contact_options), intent(in) :: options
      type(tangential_request) :: request
      request%mu = options%friction
      request%by_slip = options%by_slip
      request%load = options%tangential_load
      request%slip = options%slip
      request%tol = options%tangential_tol
      request%periodic = options%boundary == BOUNDARY_PERIODIC
   end function tangential_request_of

   !> A state's tangential step from its answer (the tractions and stick flags moved, not
   !> copied); stick_contacts counts this process's sticking contacts (on ranks, the
   !> caller sums them).
   subroutine keep_tangential_answer(answer, s)
      type(tangential_answer), intent(inout) :: answer
      type(state_values), intent(inout) :: s
      call move_alloc(answer%tx, s%shear_x)
      call move_alloc(answer%ty, s%shear_y)
      call move_alloc(answer%stick, s%stick)
      s%stick_contacts = count(s%stick)
      s%tangential_shift = answer%shift
      s%tangential_force = answer%force
      s%sliding = answer%sliding
      s%tangential_iterations = answer%iterations
      s%tangential_residual = answer%residual
   end subroutine keep_tangential_answer

   !> The tangential state of contact pixels (ci, cj) with normal forces f (nN) of
   !> `problem` under `request`, on one process (its own operator, made and freed here).
   subroutine solve_tangential(problem, ci, cj, f, request, answer, status, observer)
      type(contact_problem), intent(in) :: problem
      integer, intent(in) :: ci(:), cj(:)
      real(dp), intent(in) :: f(:)
      type(tangential_request), intent(in) :: request
      type(tangential_answer), intent(out) :: answer
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout), optional :: observer
      type(grid_shear_operator) :: op
      type(solver_observer) :: nobody
      if (status%code /= 0) return
      call grid_shear_setup(op, problem, request%periodic)
      if (present(observer)) then
         call solve_tangential_on(op, ci, cj, f, request, answer, status, observer)
      else
         call solve_tangential_on(op, ci, cj, f, request, answer, status, nobody)
      end if
      call grid_shear_free(op)
   end subroutine solve_tangential

   !> The tangential state under `request` by the operator `op`: this part's contact
   !> pixels at rows ci and columns cj (1 .. op%nj) with normal forces f (nN). `observer`
   !> is asked every 10 iterations whether to stop (a stop signal, on any part):
   !> STATUS_INTERRUPTED then. Collective over the operator's parts.
   subroutine solve_tangential_on(op, ci, cj, f, request, answer, status, observer)
      class(shear_operator), intent(inout) :: op
      integer, intent(in) :: ci(:), cj(:)
      real(dp), intent(in) :: f(:)
      type(tangential_request), intent(in) :: request
      type(tangential_answer), intent(out) :: answer
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(tangential_state) :: st
      real(dp), allocatable :: t(:, :)
      real(dp) :: totals(2)
      if (status%code /= 0) return
      st%n = size(ci)
      st%ci = ci
      st%cj = cj
      st%bound = request%mu*max(f, 0.0_dp)
      allocate(answer%tx(st%n), answer%ty(st%n), answer%stick(st%n), t(2, st%n), st%u(2, st%n))
      answer%tx = 0
      answer%ty = 0
      answer%stick = .false.
      totals = [sum(st%bound), real(st%n, dp)]
      call op%sum_over_grid(totals)
      st%capacity = totals(1)
      st%contacts = nint(totals(2))
      if (.not. st%capacity > 0) return
      allocate(st%gx(op%np, op%nj), st%gy(op%np, op%nj), st%ux(op%np, op%nj), st%uy(op%np, op%nj))
      st%gx = 0
      st%gy = 0
      if (.not. request%by_slip .and. request%load >= st%capacity*(1 - 1.0e-12_dp)) then
         call gross_sliding(st, op, request, t, answer)
      else
         t = 0
         if (.not. request%by_slip) t(1, :) = st%bound*request%load/st%capacity
         answer%shift = [request%slip, 0.0_dp]
         call projected_gradients(st, op, request, t, answer, status, observer)
      end if
      answer%tx = t(1, :)
      answer%ty = t(2, :)
      answer%force = [sum(answer%tx), sum(answer%ty)]
      call op%sum_over_grid(answer%force)
   end subroutine solve_tangential_on

   !> Q >= mu P: every pixel at its bound along x. The shift at Q = mu P is the onset's:
   !> the largest u_x, where the last pixel to stick lets go; beyond mu P it is unbounded.
   subroutine gross_sliding(st, op, request, t, answer)
      type(tangential_state), intent(inout) :: st
      class(shear_operator), intent(inout) :: op
      type(tangential_request), intent(in) :: request
      real(dp), intent(out) :: t(:, :)
      type(tangential_answer), intent(inout) :: answer
      real(dp) :: largest(1), mean(1)
      answer%sliding = .true.
      t(1, :) = st%bound
      t(2, :) = 0
      call displace(st, op, t)
      largest = maxval(st%u(1, :))
      mean = sum(st%u(2, :))
      call op%max_over_grid(largest)
      call op%sum_over_grid(mean)
      answer%shift = [largest(1), mean(1)/st%contacts]
      if (request%load > st%capacity*(1 + 1.0e-12_dp)) answer%shift = ieee_value(1.0_dp, ieee_quiet_nan)
   end subroutine gross_sliding

   !> st%u = A t at the contacts (nm), through the grids.
   subroutine displace(st, op, t)
      type(tangential_state), intent(inout) :: st
      class(shear_operator), intent(inout) :: op
      real(dp), intent(in) :: t(:, :)
      integer :: k
      do k = 1, st%n
         st%gx(st%ci(k), st%cj(k)) = t(1, k)
         st%gy(st%ci(k), st%cj(k)) = t(2, k)
      end do
      call op%displace(st%gx, st%gy, st%ux, st%uy)
      do k = 1, st%n
         st%u(1, k) = st%ux(st%ci(k), st%cj(k))
         st%u(2, k) = st%uy(st%ci(k), st%cj(k))
         st%gx(st%ci(k), st%cj(k)) = 0
         st%gy(st%ci(k), st%cj(k)) = 0
      end do
   end subroutine displace

   !> The largest |u| component over the whole grid's contacts (nm), the shift's size
   !> beside it, and never below the smallest positive number: the residuals' scale.
   real(dp) function displacement_scale(st, op, shift) result(scale)
      type(tangential_state), intent(in) :: st
      class(shear_operator), intent(inout) :: op
      real(dp), intent(in) :: shift(2)
      real(dp) :: largest(1)
      largest = maxval(abs(st%u))
      call op%max_over_grid(largest)
      scale = max(norm2(shift), largest(1), tiny(1.0_dp))
   end function displacement_scale

   !> True on every part when a stop was asked for on one (the parts stop together).
   logical function stop_asked(op, observer)
      class(shear_operator), intent(inout) :: op
      class(solver_observer), intent(inout) :: observer
      real(dp) :: asked(1)
      asked = merge(1.0_dp, 0.0_dp, observer%stop_requested())
      call op%sum_over_grid(asked)
      stop_asked = asked(1) > 0
   end function stop_asked

   !> FISTA with adaptive restart (module header) from the forces t (feasible: within the
   !> discs, and summing to Q under force control); t the answer's forces (2 x n).
   subroutine projected_gradients(st, op, request, t, answer, status, observer)
      type(tangential_state), intent(inout) :: st
      class(shear_operator), intent(inout) :: op
      type(tangential_request), intent(in) :: request
      real(dp), intent(inout) :: t(:, :)
      type(tangential_answer), intent(inout) :: answer
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), allocatable :: y(:, :), z(:, :), t_new(:, :)
      real(dp) :: step, theta, theta_new, lambda(2), shift(2), gap, best, largest(2), momentum(1)
      integer :: it
      step = 1/contact_largest(st, op)
      best = huge(1.0_dp)
      allocate(y(2, st%n), z(2, st%n), t_new(2, st%n))
      shift = answer%shift
      lambda = shift*step
      y = t
      theta = 1
      do it = 1, request%max_iterations
         if (mod(it, 10) == 0) then
            if (stop_asked(op, observer)) then
               call set_error(status, STATUS_INTERRUPTED, "stopped after "//count_text(it, "iteration")//" of the "// &
                  "tangential step")
               return
            end if
         end if
         call displace(st, op, y)
         z = y - step*st%u
         if (request%by_slip) then
            z(1, :) = z(1, :) + step*shift(1)
            z(2, :) = z(2, :) + step*shift(2)
            call project_discs(z, st%bound, t_new)
         else
            call project_with_load(op, z, st%bound, st%capacity, [request%load, 0.0_dp], lambda, t_new)
            shift = lambda/step
         end if
         ! The gradient mapping (nm): how far the step moves the forces, in displacements.
         largest = [maxval(abs(st%u)), maxval(norm2(y - t_new, dim=1))]
         call op%max_over_grid(largest)
         gap = largest(2)/step/max(norm2(shift), largest(1), tiny(1.0_dp))
         ! A step too long for A (the power iteration's estimate short of its largest
         ! eigenvalue) shows as a gap growing without bound: half the step, no momentum.
         if (gap > 1.0e3_dp*best .and. step > (1/op%largest)*(1 + 1.0e-12_dp)) then
            step = max(step/2, 1/op%largest)
            lambda = shift*step
            theta = 1
            y = t
            best = huge(1.0_dp)
            cycle
         end if
         best = min(best, gap)
         ! Adaptive restart: momentum against the last step's direction.
         momentum = sum((y - t_new)*(t_new - t))
         call op%sum_over_grid(momentum)
         if (momentum(1) > 0) then
            theta = 1
            y = t_new
         else
            theta_new = (1 + sqrt(1 + 4*theta**2))/2
            y = t_new + ((theta - 1)/theta_new)*(t_new - t)
            theta = theta_new
         end if
         t = t_new
         if (gap < request%tol) exit
      end do
      answer%iterations = min(it, request%max_iterations)
      call displace(st, op, t)
      answer%shift = shift
      call classify(st, op, t, shift, answer)
      if (answer%residual > 10*request%tol) call set_error(status, STATUS_NUMERICAL, "tangential: residual "// &
         sig_str(answer%residual, 2)//" after "//count_text(answer%iterations, "iteration")//", above 10 x --tol "// &
         sig_str(request%tol, 2))
   end subroutine projected_gradients

   !> A bound on the largest eigenvalue of A on the contacts (nm/nN), the step's inverse:
   !> power iteration (20 products, from the bounds along x and y) gives it from below,
   !> to within the ratio of its two largest; 1.25 times that, and never more than the
   !> padded operator's bound, which holds on any set but is the whole grid's (the
   !> lowest frequency's, ~ NP) where a rough surface's contacts are a few per cent of it.
   real(dp) function contact_largest(st, op) result(largest)
      type(tangential_state), intent(inout) :: st
      class(shear_operator), intent(inout) :: op
      real(dp), allocatable :: x(:, :)
      real(dp) :: total(1)
      integer :: it
      allocate(x(2, st%n))
      x(1, :) = st%bound
      x(2, :) = st%bound/2
      largest = 0
      do it = 1, 20
         x = x/op%norm_over_grid(x)
         call displace(st, op, x)
         total = sum(x*st%u)
         call op%sum_over_grid(total)
         largest = total(1)
         x = st%u
      end do
      largest = min(1.25_dp*largest, op%largest)
   end function contact_largest

   !> Stick and slip from the forces t and the displacements st%u at the shift, and the
   !> largest violation of their conditions over the shift's size: a sticking pixel moves
   !> with the shift; a slipping one lags behind it along its force.
   subroutine classify(st, op, t, shift, answer)
      type(tangential_state), intent(in) :: st
      class(shear_operator), intent(inout) :: op
      real(dp), intent(in) :: t(:, :), shift(2)
      type(tangential_answer), intent(inout) :: answer
      real(dp) :: v(2), along, r, scale, residual(1)
      integer :: k
      scale = displacement_scale(st, op, shift)
      residual = 0
      do k = 1, st%n
         v = shift - st%u(:, k)
         answer%stick(k) = norm2(t(:, k)) < st%bound(k)*(1 - 1.0e-9_dp)
         if (answer%stick(k)) then
            r = norm2(v)
         else
            along = dot_product(v, t(:, k))/norm2(t(:, k))
            r = norm2(v - along*t(:, k)/norm2(t(:, k))) + max(0.0_dp, -along)
         end if
         residual = max(residual, r/scale)
      end do
      call op%max_over_grid(residual)
      answer%residual = residual(1)
   end subroutine classify

   !> t_k = the projection of z_k onto the disc of radius b_k.
   pure subroutine project_discs(z, b, t)
      real(dp), intent(in) :: z(:, :), b(:)
      real(dp), intent(out) :: t(:, :)
      real(dp) :: r
      integer :: k
      do k = 1, size(b)
         r = norm2(z(:, k))
         if (r <= b(k)) then
            t(:, k) = z(:, k)
         else
            t(:, k) = z(:, k)*(b(k)/r)
         end if
      end do
   end subroutine project_discs

   !> The projection of z onto {|t_k| <= b_k, sum t = q} (over the whole grid's contacts;
   !> `capacity` the sum of the bounds): t_k = P_k(z_k + lambda), lambda (warm-started)
   !> the root of sum P_k(z_k + lambda) = q by Newton's method with halving steps; the
   !> Jacobian sum of I (inside) and (b/|w|)(I - w w^T/|w|^2) (outside).
   subroutine project_with_load(op, z, b, capacity, q, lambda, t)
      class(shear_operator), intent(inout) :: op
      real(dp), intent(in) :: z(:, :), b(:), capacity, q(2)
      real(dp), intent(inout) :: lambda(2)
      real(dp), intent(out) :: t(:, :)
      real(dp) :: jac(2, 2), f(2), trial(2), step(2), det, residual, target
      integer :: it, halving
      target = 1.0e-14_dp*capacity
      call load_equation(op, z, b, q, lambda, f, jac)
      residual = norm2(f)
      do it = 1, 200
         if (residual <= target) exit
         jac(1, 1) = jac(1, 1) + 1.0e-12_dp*(jac(1, 1) + jac(2, 2))
         jac(2, 2) = jac(2, 2) + 1.0e-12_dp*(jac(1, 1) + jac(2, 2))
         det = jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)
         step = -[jac(2, 2)*f(1) - jac(1, 2)*f(2), jac(1, 1)*f(2) - jac(2, 1)*f(1)]/det
         do halving = 0, 40
            trial = lambda + step/2.0_dp**halving
            call load_equation(op, z, b, q, trial, f, jac)
            if (norm2(f) < residual) exit
         end do
         lambda = trial
         residual = norm2(f)
      end do
      call project_discs(z + spread(lambda, 2, size(b)), b, t)
   end subroutine project_with_load

   !> f = sum P_k(z_k + l) - q over the whole grid's contacts and its Jacobian in l
   !> (project_with_load). The part holding column 0 starts from -q, the others from 0.
   subroutine load_equation(op, z, b, q, l, f, jac)
      class(shear_operator), intent(inout) :: op
      real(dp), intent(in) :: z(:, :), b(:), q(2), l(2)
      real(dp), intent(out) :: f(2), jac(2, 2)
      real(dp) :: w(2), r, sums(6)
      integer :: k
      f = 0
      if (op%j0 == 0) f = -q
      jac = 0
      do k = 1, size(b)
         w = z(:, k) + l
         r = norm2(w)
         if (r <= b(k)) then
            f = f + w
            jac(1, 1) = jac(1, 1) + 1
            jac(2, 2) = jac(2, 2) + 1
         else
            f = f + w*(b(k)/r)
            jac(1, 1) = jac(1, 1) + b(k)/r*(1 - w(1)**2/r**2)
            jac(2, 2) = jac(2, 2) + b(k)/r*(1 - w(2)**2/r**2)
            jac(1, 2) = jac(1, 2) - b(k)/r*w(1)*w(2)/r**2
            jac(2, 1) = jac(1, 2)
         end if
      end do
      sums = [f, reshape(jac, [4])]
      call op%sum_over_grid(sums)
      f = sums(1:2)
      jac = reshape(sums(3:6), [2, 2])
   end subroutine load_equation

   !> The bytes the tangential step holds at NP (the padded grid's fields and spectra,
   !> the four grids, three spectra): for the memory check.
   pure integer(i8) function tangential_storage_bytes(np) result(bytes)
      integer, intent(in) :: np
      bytes = int(np, i8)**2*(8*4 + 8*4 + 16*2*2 + 8*3*2)
   end function tangential_storage_bytes
end module femcod_tangential
