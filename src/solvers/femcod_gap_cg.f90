!> Contact under displacement control in the gap variables, with the interface law and
!> bounds (model/femcod_interface_law) as arguments: adhesive (`--adhesion
!> dugdale|exponential --work W --range R --approach D1,D2,...`, with `--solver cg`) or the
!> hard wall (phi = 0) with the plastic cap (`--solver cg --plastic --approach ...`); the
!> cap fmax = H d^2 bounds every pixel's force with any law. femcod_cg's solve_target
!> calls it for those targets, on one core and on MPI ranks alike: everything over the
!> grid goes through the elastic operator (its transform grid, apply_spectrum, and its
!> reductions). At each prescribed approach A,
!> in the order given, a local minimum of the total energy
!>     Pi(u) = 1/2 u.K u + d^2 sum_i phi(g_i),   g = g0 - A + u >= 0,
!> continued from the state at the previous approach, so that loading and unloading
!> follow their own branches (hysteresis) and jumps into contact and pull-off show.
!> u (nm) is the surface separation the forces cause, F = K u the pixel forces (nN,
!> compression positive, tension negative), K the inverse of the composite compliance
!> C = c (I * .) + s of the other solvers (Love kernel, springs' 3/k), g0 the composite
!> initial gap, d the pixel. The adhesive potential per area, with work of adhesion W
!> (nN/nm = J/m^2) and range R (nm):
!>     Dugdale:      phi(g) = -W (1 - g/R) for g < R, 0 beyond (a tension W/R within R),
!>     exponential:  phi(g) = -W exp(-g/R)            (a tension (W/R) exp(-g/R)).
!> Stationarity: F = -d^2 phi'(g) wherever g > 0 (the adhesive tension, zero beyond the
!> range), F >= -d^2 phi'(0) on the contact (g = 0).
!>
!> The path: from one approach to the next in substeps of at most R/2 (quasi-static
!> continuation; at most 1000), each from the last state; the first approach from the
!> undeformed surfaces.
!>
!> Method: the constrained conjugate gradients in the gap variables of Rey, Anciaux and
!> Molinari (Comput. Mech. 60, 2017, 69-81; tamaas' solver for these functionals): the
!> gradient r = K u + d^2 phi'(g), a search direction on the free set (g > 0, or g = 0
!> with r < 0: the pixels that may move), a step along it, projection onto g >= 0.
!> K is diagonal in Fourier space: on a periodic cell the grid is the cell; on the free
!> half-space the unknowns live on the zero-padded (2 NP)^2 grid (the operator's transform
!> field: on ranks each holds its columns of it), where no force may act
!> on the padding (its residual is part of the stopping rule), so that u on the grid is
!> exactly c (I * F) + s F of the forces on the grid (the padding keeps every image out,
!> as in ContactMechanics' free FFT half-space). Two additions, neither changing the
!> answer: the search direction is preconditioned by C, the exact inverse of K (masked to
!> the free set), which removes the |q| spread of K's spectrum and the stiff
!> zero-frequency mode of a periodic cell; beta is Polak-Ribiere clipped at zero. The step
!> is the minimum of the quadratic model along the direction with the adhesive curvature
!> d^2 phi'' included where it keeps the model convex, the elastic curvature alone
!> otherwise (Rey et al.).
!>
!> Stopping rule: the largest violation of the conditions above, |r| on a pixel off
!> contact or on the padding, max(-r, 0) on a contact, times one pixel's compliance
!> c I(0,0) + s (the gap it would move) over the height range, below `tol`: the fixed-load
!> solver's measure.
!>
!> Bugnicourt et al. (Tribol. Lett. 66, 2018, 29) show that such solutions converge with
!> the mesh only when the pixel resolves the range, and that the iteration converges while
!> the adhesive stiffness W d^2 / R^2 of one pixel stays below its elastic stiffness:
!> the summary reports both numbers (`adhesion_convexity`).
module femcod_gap_cg
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_INTERRUPTED, STATUS_USAGE, STATUS_NUMERICAL
   use femcod_problem, only: contact_problem
   use femcod_love, only: surface_compliance, love_influence
   use femcod_spring, only: spring_stiffness
   use femcod_elastic_operator, only: elastic_operator, SPECTRUM_COMPLIANCE, SPECTRUM_STIFFNESS
   use femcod_interface_law, only: interface_law, pixel_tension, MAX_PLASTIC_ROUNDS
   use femcod_observer, only: solver_observer
   use femcod_strings, only: int_str, sig_str, format_real
   implicit none
   private
   public :: gap_session, gap_session_start, gap_target, pixel_stiffness_ratio, gap_solver_storage_bytes

   !> Substeps between two approaches at most (each at most half the range otherwise).
   integer, parameter :: MAX_SUBSTEPS = 1000

   !> What the path carries from one approach to the next, on this part's columns: the
   !> separations x (nm) on the transform field (tm, tmj), and on the pixels (np, nj) the
   !> gaps (nm), the forces (nN), the plastic displacement (nm, permanent: it raises the
   !> initial gap for the rest of the path) and the capped pixels; the last approach (nm).
   type :: gap_session
      real(dp), allocatable :: x(:, :), g(:, :), force(:, :), plastic(:, :)
      logical, allocatable :: cap(:, :)
      real(dp) :: last = 0
      logical :: started = .false.
   end type gap_session

   !> The iteration's work on the transform field (tm, tmj): K x, the gradient r, the
   !> preconditioned z, the direction d, w = K d, the last gradient, the free set; on the
   !> pixels the adhesive curvature; the scalars carried between its steps.
   type :: gap_iteration
      real(dp), allocatable :: kx(:, :), r(:, :), z(:, :), d(:, :), w(:, :), r_old(:, :), curvature(:, :)
      logical, allocatable :: free(:, :)
      !> The height range (nm), the periodic cell's mean gap (nm), its multiplier (nN),
      !> r.d, the last z.r.
      real(dp) :: scale = 1, mean_gap = 0, mu = 0, rd = 0, rz_old = 0
      integer :: round = 1
   end type gap_iteration

contains

   !> The ratio of one pixel's largest adhesive stiffness, d^2 W / R^2, to its elastic
   !> stiffness 1/(c I(0,0) + s) (nondimensional): the iteration is safely convex below 1
   !> (Bugnicourt et al. 2018). Dugdale's law has no curvature but a jump at R of W/R.
   pure real(dp) function pixel_stiffness_ratio(problem, work, range)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: work, range
      real(dp) :: c
      c = surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), problem%pixel)
      pixel_stiffness_ratio = problem%pixel**2*work/range**2* &
         (c*love_influence(0, 0) + 3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel))
   end function pixel_stiffness_ratio

   !> The gap-variable solver's storage at its largest (bytes), from what it allocates on
   !> the transform grid of M^2 points (M = 2 NP free, NP periodic): the field (8), the
   !> spectrum (8: complex on half the points), the compliance and stiffness spectra (8),
   !> the separations (8) and the iteration's K x, r, z, d, w, r_old (48) and free flags
   !> (4); on the NP^2 pixels the gaps of the deck, the solution and the forces, the
   !> plastic displacement, tension and curvature (48), the capped flags (4); each state's
   !> gap map (8) and, with the plastic cap, its plastic map (8).
   pure function gap_solver_storage_bytes(np, nstates, periodic, plastic) result(bytes)
      integer, intent(in) :: np, nstates
      logical, intent(in) :: periodic, plastic
      integer(i8) :: bytes, m2, n2
      n2 = int(np, i8)**2
      m2 = merge(n2, 4*n2, periodic)
      bytes = m2*(8 + 8 + 8 + 8 + 48 + 4) + n2*(48 + 4 + 8*nstates)
      if (plastic) bytes = bytes + n2*8*nstates
   end function gap_solver_storage_bytes

   !> A path on `op` (made with its transform grid): undeformed, nothing capped.
   subroutine gap_session_start(op, session)
      class(elastic_operator), intent(in) :: op
      type(gap_session), intent(out) :: session
      allocate(session%x(op%tm, op%tmj), session%g(op%np, op%nj), session%force(op%np, op%nj), &
         session%plastic(op%np, op%nj), session%cap(op%np, op%nj))
      session%x = 0
      session%g = 0
      session%force = 0
      session%plastic = 0
      session%cap = .false.
      session%last = 0
      session%started = .false.
   end subroutine gap_session_start

   !> The state at the approach `a` (nm) on the path (quasi-static continuation, module
   !> header): from the last approach in substeps of at most half the range with an
   !> adhesive law (the first approach from the undeformed surfaces), each solved to `tol`
   !> in at most `max_iterations`; with the cap, a pixel that yielded keeps its
   !> interpenetration as plastic displacement, and its gap (of the deformed surfaces) is
   !> 0. g0: this part's initial gaps (nm). `iterations` over every substep; `residual` of
   !> the last.
   subroutine gap_target(op, law, session, g0, a, tol, max_iterations, iterations, residual, status, observer)
      class(elastic_operator), intent(inout) :: op
      type(interface_law), intent(in) :: law
      type(gap_session), intent(inout) :: session
      real(dp), intent(in) :: g0(:, :), a, tol
      integer, intent(in) :: max_iterations
      integer, intent(out) :: iterations
      real(dp), intent(out) :: residual
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp) :: target, smallest(1)
      integer :: nsub, sub, n
      iterations = 0
      residual = 0
      smallest(1) = op%smallest_compliance
      call op%min_over_grid(smallest)
      if (op%tm == 0 .or. .not. smallest(1) > 0) then
         call set_error(status, STATUS_NUMERICAL, "the gap-variable iteration: the compliance's spectrum on the "// &
            "transform grid is not positive (smallest "//sig_str(smallest(1), 3)//" nm/nN)")
         return
      end if
      nsub = 1
      if (session%started .and. law%adhesive()) &
         nsub = min(MAX_SUBSTEPS, max(1, ceiling(abs(a - session%last)/(law%range/2))))
      do sub = 1, nsub
         target = a
         if (sub < nsub) target = session%last + (a - session%last)*real(sub, dp)/nsub
         call gap_cg(op, law, g0 + session%plastic, target, tol, max_iterations, session%x, session%g, &
            session%force, session%cap, n, residual, status, observer)
         iterations = iterations + n
         if (status%code /= 0) return
         if (law%capped()) then
            ! A capped pixel carries fmax by the law (its residual, K x + mu - fmax, is
            ! within the tolerance): exactly, so that no pressure above H is reported.
            where (session%cap) session%force = law%fmax
            session%plastic = session%plastic + max(-session%g, 0.0_dp)
            session%g = max(session%g, 0.0_dp)
         end if
      end do
      session%last = a
      session%started = .true.
   end subroutine gap_target

   !> The constrained conjugate gradients at approach `a` (nm) from the separations x
   !> (nm, transform field; returned: the solution). Returned besides: the gaps g (nm,
   !> this part's pixels, exactly 0 on the contact) and the pixel forces (nN).
   !> On a periodic cell the approach fixes the mean gap, mean g0 - a (the zero-frequency
   !> compliance is left out: a uniform pressure has no finite displacement there), and
   !> the mean force is the constraint's multiplier mu: the gradient is r = K x + mu +
   !> d^2 phi'(g), mu making its mean over the open pixels zero; directions have zero
   !> mean; after a projection the open gaps are shifted back to the mean gap (Rey et al.).
   !> With the cap law%fmax, by rounds on the capped set as the fixed-load solver's
   !> capped_solve: the capped pixels carry fmax whatever their gap (a constant gradient,
   !> unbounded: below 0 they interpenetrate), the others are solved as above; then the
   !> contacts above fmax join the set and the capped pixels whose gap opened leave it,
   !> until neither happens (law%plastic_round; at most MAX_PLASTIC_ROUNDS, else exit 4).
   subroutine gap_cg(op, law, g0, a, tol, max_iterations, x, g, force, cap, iterations, residual, status, observer)
      class(elastic_operator), intent(inout) :: op
      type(interface_law), intent(in) :: law
      real(dp), intent(in) :: g0(:, :), a, tol
      integer, intent(in) :: max_iterations
      real(dp), intent(inout) :: x(:, :)
      real(dp), intent(out) :: g(:, :), force(:, :)
      !> The capped pixels (with the cap): carried from the last state, returned updated.
      logical, intent(inout) :: cap(:, :)
      integer, intent(out) :: iterations
      real(dp), intent(out) :: residual
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(gap_iteration) :: it
      logical :: descends
      iterations = 0
      residual = huge(1.0_dp)
      call iteration_start(op, law, g0, a, x, g, cap, it, status)
      if (status%code /= 0) return
      do
         call gradient(op, law, g, cap, it)
         call free_set(op, g, cap, it, residual)
         if (residual <= tol .and. law%capped()) then
            if (next_round(op, law, g, cap, it)) then
               if (it%round <= MAX_PLASTIC_ROUNDS) cycle
               call set_error(status, STATUS_NUMERICAL, "cg --plastic: the plastic set did not settle in "// &
                  int_str(MAX_PLASTIC_ROUNDS)//" rounds at the approach "//format_real(a)//" nm")
               return
            end if
         end if
         if (residual <= tol .or. iterations >= max_iterations) exit
         if (op%any_over_grid(observer%stop_requested())) then
            call set_error(status, STATUS_INTERRUPTED, "stopped after "//int_str(iterations)// &
               " iterations at the approach "//format_real(a)//" nm")
            return
         end if
         iterations = iterations + 1
         call search_direction(op, it)
         call take_step(op, g0, a, x, g, cap, it, descends)
         if (.not. descends) exit
      end do
      ! The answer's forces from a fresh transform of its separations (on a periodic cell
      ! plus the mean force, the multiplier).
      call op%apply_spectrum(SPECTRUM_STIFFNESS, x, it%kx)
      force = it%kx(1:op%np, 1:op%nj) + it%mu
   end subroutine gap_cg

   !> The iteration's arrays, the height range, the periodic cell's mean gap (refused at
   !> or beyond full contact), and the first gaps: the separations' projected onto g >= 0.
   subroutine iteration_start(op, law, g0, a, x, g, cap, it, status)
      class(elastic_operator), intent(inout) :: op
      type(interface_law), intent(in) :: law
      real(dp), intent(in) :: g0(:, :), a
      real(dp), intent(inout) :: x(:, :)
      real(dp), intent(out) :: g(:, :)
      logical, intent(inout) :: cap(:, :)
      type(gap_iteration), intent(out) :: it
      type(status_type), intent(inout) :: status
      real(dp) :: top(1), bottom(1), total(1)
      integer :: np, nj
      np = op%np
      nj = op%nj
      allocate(it%kx(op%tm, op%tmj), it%r(op%tm, op%tmj), it%z(op%tm, op%tmj), it%d(op%tm, op%tmj), &
         it%w(op%tm, op%tmj), it%r_old(op%tm, op%tmj), it%free(op%tm, op%tmj), it%curvature(np, nj))
      it%mean_gap = 0
      if (op%periodic) then
         total(1) = sum(g0)
         call op%sum_over_grid(total)
         it%mean_gap = total(1)/real(np, dp)**2 - a
         if (.not. it%mean_gap > 0) then
            call set_error(status, STATUS_USAGE, "adhesion: the approach "//format_real(a)//" nm closes the "// &
               "periodic cell's mean gap (mean g0 = "//format_real(total(1)/real(np, dp)**2)//" nm): full contact")
            return
         end if
      end if
      if (.not. law%capped()) cap = .false.
      it%round = 1
      top(1) = maxval(g0)
      bottom(1) = minval(g0)
      call op%max_over_grid(top)
      call op%min_over_grid(bottom)
      ! The height range, or the approach where larger (a flat or nearly flat surface).
      it%scale = max(top(1) - bottom(1), abs(a), tiny(1.0_dp))
      g = g0 - a + x(1:np, 1:nj)
      call project(op, it, cap, g)
      x(1:np, 1:nj) = g - g0 + a
      call op%apply_spectrum(SPECTRUM_STIFFNESS, x, it%kx)
      it%d = 0
      it%r_old = 0
      it%rz_old = 0
   end subroutine iteration_start

   !> The gradient r = K x (+ the adhesive tension, or -fmax on a capped pixel) and the
   !> pixels' adhesive curvature; on a periodic cell the multiplier mu that makes r's mean
   !> over the open pixels zero (over all pixels when none is open).
   subroutine gradient(op, law, g, cap, it)
      class(elastic_operator), intent(inout) :: op
      type(interface_law), intent(in) :: law
      real(dp), intent(in) :: g(:, :)
      logical, intent(in) :: cap(:, :)
      type(gap_iteration), intent(inout) :: it
      real(dp) :: open_sum, open_count, t, cv, total(2)
      real(dp), allocatable :: columns(:, :)
      integer :: i, j, np, nj
      np = op%np
      nj = op%nj
      ! Sums by column, then the columns in order: the same bits on any number of threads.
      allocate(columns(2, op%tmj))
      !$omp parallel do private(i, t, cv)
      do j = 1, op%tmj
         columns(:, j) = 0
         do i = 1, op%tm
            if (i <= np .and. j <= nj) then
               if (cap(i, j)) then
                  t = -law%fmax
                  cv = 0
               else
                  call pixel_tension(law, max(g(i, j), 0.0_dp), t, cv)
               end if
               it%curvature(i, j) = cv
               it%r(i, j) = it%kx(i, j) + t
               if (g(i, j) > 0) then
                  columns(1, j) = columns(1, j) + it%r(i, j)
                  columns(2, j) = columns(2, j) + 1
               end if
            else
               it%r(i, j) = it%kx(i, j)
            end if
         end do
      end do
      !$omp end parallel do
      open_sum = sum(columns(1, :))
      open_count = sum(columns(2, :))
      it%mu = 0
      if (.not. op%periodic) return
      total = [open_sum, open_count]
      call op%sum_over_grid(total)
      if (total(2) > 0) then
         it%mu = -total(1)/total(2)
      else
         total(1) = sum(it%r)
         call op%sum_over_grid(total(1:1))
         it%mu = -total(1)/real(np, dp)**2
      end if
   end subroutine gradient

   !> r += mu; the free set (an open gap, a contact that pulls, a capped pixel, the
   !> padding), and the largest violation of the conditions, as the gap it would move on
   !> one pixel (c I(0,0) + s), over the height range: the fixed-load solver's measure.
   subroutine free_set(op, g, cap, it, residual)
      class(elastic_operator), intent(inout) :: op
      real(dp), intent(in) :: g(:, :)
      logical, intent(in) :: cap(:, :)
      type(gap_iteration), intent(inout) :: it
      real(dp), intent(out) :: residual
      real(dp) :: worst(1), mu
      integer :: i, j, np, nj
      np = op%np
      nj = op%nj
      mu = it%mu
      worst(1) = 0
      !$omp parallel do private(i) reduction(max:worst)
      do j = 1, op%tmj
         do i = 1, op%tm
            it%r(i, j) = it%r(i, j) + mu
            if (i <= np .and. j <= nj) then
               it%free(i, j) = g(i, j) > 0 .or. it%r(i, j) < 0 .or. cap(i, j)
            else
               it%free(i, j) = .true.
            end if
            if (it%free(i, j)) then
               worst(1) = max(worst(1), abs(it%r(i, j)))
            else
               worst(1) = max(worst(1), -it%r(i, j))
            end if
         end do
      end do
      !$omp end parallel do
      call op%max_over_grid(worst)
      residual = worst(1)*(op%c*op%self + op%s)/it%scale
   end subroutine free_set

   !> A round of the capped set ends (law%plastic_round): pixels in contact above the cap
   !> join it, capped pixels whose gap opened leave it. True (the round counted and the
   !> directions restarted) when either happened on any rank.
   logical function next_round(op, law, g, cap, it) result(again)
      class(elastic_operator), intent(inout) :: op
      type(interface_law), intent(in) :: law
      real(dp), intent(in) :: g(:, :)
      logical, intent(inout) :: cap(:, :)
      type(gap_iteration), intent(inout) :: it
      logical, allocatable :: join(:, :), leave(:, :)
      allocate(join(op%np, op%nj), leave(op%np, op%nj))
      ! A pixel's force: K x + mu on the contacts; off them the adhesive tension (or 0),
      ! never above the cap.
      call law%plastic_round(merge(it%kx(1:op%np, 1:op%nj) + it%mu, 0.0_dp, g == 0), g, 0.0_dp, cap, join, &
         leave)
      again = op%any_over_grid(any(join) .or. any(leave))
      if (.not. again) return
      it%round = it%round + 1
      it%d = 0
      it%rz_old = 0
   end function next_round

   !> The search direction on the free set: z = C r there (preconditioned), beta by
   !> Polak-Ribiere clipped at zero, and steepest descent when that direction does not
   !> descend.
   subroutine search_direction(op, it)
      class(elastic_operator), intent(inout) :: op
      type(gap_iteration), intent(inout) :: it
      real(dp) :: products(2), beta
      integer :: i, j
      !$omp parallel do private(i)
      do j = 1, op%tmj
         do i = 1, op%tm
            if (.not. it%free(i, j)) it%r(i, j) = 0
         end do
      end do
      !$omp end parallel do
      call op%apply_spectrum(SPECTRUM_COMPLIANCE, it%r, it%z)
      call free_products(it, products)
      call op%sum_over_grid(products)
      beta = 0
      if (it%rz_old > 0) beta = max(0.0_dp, (products(1) - products(2))/it%rz_old)
      call new_direction(op, it, beta)
      if (it%rd >= 0) call new_direction(op, it, 0.0_dp)
      it%rz_old = products(1)
   end subroutine search_direction

   !> z zeroed off the free set; products = [r.z, z.r_old] on this part.
   subroutine free_products(it, products)
      type(gap_iteration), intent(inout) :: it
      real(dp), intent(out) :: products(2)
      real(dp), allocatable :: columns(:, :)
      integer :: i, j
      ! Sums by column, then the columns in order: the same bits on any number of threads.
      allocate(columns(2, size(it%z, 2)))
      !$omp parallel do private(i)
      do j = 1, size(it%z, 2)
         columns(:, j) = 0
         do i = 1, size(it%z, 1)
            if (.not. it%free(i, j)) it%z(i, j) = 0
            columns(1, j) = columns(1, j) + it%r(i, j)*it%z(i, j)
            columns(2, j) = columns(2, j) + it%z(i, j)*it%r_old(i, j)
         end do
      end do
      !$omp end parallel do
      products = [sum(columns(1, :)), sum(columns(2, :))]
   end subroutine free_products

   !> d = -z + b d on the free set (0 elsewhere), with zero mean over the free set on a
   !> periodic cell (the mean gap is held); rd = r.d; r_old = r.
   subroutine new_direction(op, it, b)
      class(elastic_operator), intent(inout) :: op
      type(gap_iteration), intent(inout) :: it
      real(dp), intent(in) :: b
      real(dp) :: total, nfree, shift, counts(2), rd(1)
      real(dp), allocatable :: columns(:, :)
      integer :: i, j
      ! Sums by column, then the columns in order: the same bits on any number of threads.
      allocate(columns(2, op%tmj))
      !$omp parallel do private(i)
      do j = 1, op%tmj
         columns(:, j) = 0
         do i = 1, op%tm
            if (it%free(i, j)) then
               it%d(i, j) = -it%z(i, j) + b*it%d(i, j)
               columns(1, j) = columns(1, j) + it%d(i, j)
               columns(2, j) = columns(2, j) + 1
            else
               it%d(i, j) = 0
            end if
         end do
      end do
      !$omp end parallel do
      total = sum(columns(1, :))
      nfree = sum(columns(2, :))
      shift = 0
      if (op%periodic) then
         counts = [total, nfree]
         call op%sum_over_grid(counts)
         if (counts(2) > 0) shift = counts(1)/counts(2)
      end if
      !$omp parallel do private(i)
      do j = 1, op%tmj
         columns(1, j) = 0
         do i = 1, op%tm
            if (it%free(i, j)) it%d(i, j) = it%d(i, j) - shift
            columns(1, j) = columns(1, j) + it%r(i, j)*it%d(i, j)
            it%r_old(i, j) = it%r(i, j)
         end do
      end do
      !$omp end parallel do
      rd(1) = sum(columns(1, :))
      call op%sum_over_grid(rd)
      it%rd = rd(1)
   end subroutine new_direction

   !> The step along d: the minimum of the quadratic model, with the adhesive curvature
   !> where it keeps the model convex (the elastic curvature alone otherwise); the gaps
   !> move with the separations, and a contact off the free set that the step would open
   !> below 0 is projected back (then K x afresh). `descends` false: no positive
   !> curvature (the iteration stops).
   subroutine take_step(op, g0, a, x, g, cap, it, descends)
      class(elastic_operator), intent(inout) :: op
      real(dp), intent(in) :: g0(:, :), a
      real(dp), intent(inout) :: x(:, :), g(:, :)
      logical, intent(in) :: cap(:, :)
      type(gap_iteration), intent(inout) :: it
      logical, intent(out) :: descends
      real(dp) :: curv, adhesive_curv, tau, sums(2)
      real(dp), allocatable :: columns(:, :)
      integer :: i, j, np, nj
      logical :: clipped
      np = op%np
      nj = op%nj
      call op%apply_spectrum(SPECTRUM_STIFFNESS, it%d, it%w)
      ! Sums by column, then the columns in order: the same bits on any number of threads.
      allocate(columns(2, op%tmj))
      !$omp parallel do private(i)
      do j = 1, op%tmj
         columns(:, j) = 0
         do i = 1, op%tm
            columns(1, j) = columns(1, j) + it%d(i, j)*it%w(i, j)
            if (i <= np .and. j <= nj) columns(2, j) = columns(2, j) + it%curvature(i, j)*it%d(i, j)**2
         end do
      end do
      !$omp end parallel do
      curv = sum(columns(1, :))
      adhesive_curv = sum(columns(2, :))
      sums = [curv, adhesive_curv]
      call op%sum_over_grid(sums)
      curv = sums(1)
      if (sums(1) + sums(2) > 0.5_dp*sums(1)) curv = sums(1) + sums(2)
      descends = curv > 0
      if (.not. descends) return
      tau = -it%rd/curv
      clipped = .false.
      !$omp parallel do private(i) reduction(.or.:clipped)
      do j = 1, op%tmj
         do i = 1, op%tm
            x(i, j) = x(i, j) + tau*it%d(i, j)
            it%kx(i, j) = it%kx(i, j) + tau*it%w(i, j)
            if (i <= np .and. j <= nj) then
               g(i, j) = g(i, j) + tau*it%d(i, j)
               clipped = clipped .or. (g(i, j) < 0 .and. .not. cap(i, j))
            end if
         end do
      end do
      !$omp end parallel do
      if (op%any_over_grid(clipped)) then
         call project(op, it, cap, g)
         x(1:np, 1:nj) = g - g0 + a
         call op%apply_spectrum(SPECTRUM_STIFFNESS, x, it%kx)
      end if
   end subroutine take_step

   !> g >= 0 off the capped set; on a periodic cell the open gaps then shifted to the
   !> mean gap, and again, until no open gap went below 0.
   subroutine project(op, it, cap, gaps)
      class(elastic_operator), intent(inout) :: op
      type(gap_iteration), intent(in) :: it
      logical, intent(in) :: cap(:, :)
      real(dp), intent(inout) :: gaps(:, :)
      real(dp) :: total(2), n2
      integer :: pass
      logical :: open(size(gaps, 1), size(gaps, 2))
      where (.not. cap) gaps = max(gaps, 0.0_dp)
      if (.not. op%periodic) return
      n2 = real(op%np, dp)**2
      do pass = 1, 100
         open = gaps > 0 .and. .not. cap
         if (.not. op%any_over_grid(any(open))) exit
         total = [sum(gaps), real(count(open), dp)]
         call op%sum_over_grid(total)
         where (open) gaps = gaps + (it%mean_gap - total(1)/n2)*n2/total(2)
         if (.not. op%any_over_grid(any(open .and. gaps < 0))) exit
         where (open .and. gaps < 0) gaps = 0
      end do
   end subroutine project
end module femcod_gap_cg
