!> Contact under displacement control in the gap variables, with an interface law and
!> bounds as arguments: adhesive (`--adhesion dugdale|exponential --work W --range R
!> --approach D1,D2,...`, with `--solver cg`) or the hard wall (law "none", phi = 0) with
!> the plastic cap (`--solver cg --plastic --approach ...`); the cap H d^2 bounds every
!> pixel's force with any law. At each prescribed approach A,
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
!> half-space the unknowns live on the zero-padded (2 NP)^2 grid, where no force may act
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
module femcod_adhesion
   use, intrinsic :: iso_c_binding, only: c_ptr, c_double, c_double_complex, c_size_t, c_int, c_f_pointer
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED, STATUS_USAGE
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gap_map
   use femcod_love, only: offset_table, surface_compliance, love_influence
   use femcod_love_periodic, only: periodic_offset_table
   use femcod_spring, only: spring_stiffness
   use femcod_fftw, only: fftw_plan_dft_r2c_2d, fftw_plan_dft_c2r_2d, fftw_execute_dft_r2c, fftw_execute_dft_c2r, &
      fftw_destroy_plan, fftw_alloc_real, fftw_alloc_complex, fftw_free, FFTW_ESTIMATE, fftw_init_threads, &
      fftw_plan_with_nthreads
   use femcod_contact_result, only: contact_result, append_step, STOP_LOADS, gather_contacts
   use femcod_solver_options, only: contact_options, refuse_beyond_memory
   use femcod_observer, only: solver_observer
   use femcod_strings, only: int_str, sig_str, format_real
   use femcod_clock, only: wall_clock
   !$ use omp_lib, only: omp_get_max_threads
   implicit none
   private
   public :: solve_adhesive, pixel_stiffness_ratio, gap_solver_storage_bytes

   !> Rounds of the capped set per solve at most.
   integer, parameter :: MAX_ROUNDS = 200

   !> The operators on the transform grid: FFTW plans and buffers, the compliance and
   !> stiffness spectra (each divided by M^2 for FFTW's unnormalised transforms).
   type :: fourier_grid
      integer :: np = 0, m = 0
      !> One cell of a periodic surface (no padding; the mean gap is held, above).
      logical :: periodic = .false.
      !> One pixel's compliance c I(0,0) + s (nm/nN): a force residual times it is the gap
      !> it would move.
      real(dp) :: pixel_compliance = 0
      real(dp), allocatable :: compliance(:, :), stiffness(:, :)
      type(c_ptr) :: forward, backward, real_mem, complex_mem
      real(c_double), pointer :: field(:, :) => null()
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
   end type fourier_grid

contains

   !> The adhesive tension d^2 phi'(g) of one pixel (nN, positive: it pulls the surfaces
   !> together), and the curvature d^2 phi''(g) (nN/nm), for gap g >= 0 (nm); the law as
   !> a code (1 Dugdale, 2 exponential, else none) for the solver's inner loops.
   pure subroutine pixel_tension(code, work, range, area, g, tension, curvature)
      integer, intent(in) :: code
      real(dp), intent(in) :: work, range, area, g
      real(dp), intent(out) :: tension, curvature
      tension = 0
      curvature = 0
      if (code == 1) then
         if (g < range) tension = area*work/range
      else if (code == 2) then
         tension = area*(work/range)*exp(-g/range)
         curvature = -tension/range
      end if
   end subroutine pixel_tension

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

   !> The states at options%approaches (nm), in the order given, each from the last.
   subroutine solve_adhesive(problem, options, res, status, observer)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(fourier_grid) :: grid
      real(dp), allocatable :: g0(:, :), x(:, :), g(:, :), force(:, :), plastic(:, :)
      logical, allocatable :: cap(:, :)
      real(dp) :: tstart, t0, t1, area, fmax
      integer :: np, k, m, i, previous_contacts, nsub, sub, iterations
      real(dp) :: last, target
      !> Substeps between two approaches at most (each at most half the range otherwise).
      integer, parameter :: MAX_SUBSTEPS = 1000
      character(len=:), allocatable :: law
      call wall_clock(tstart)
      law = trim(options%adhesion)
      if (.not. allocated(options%approaches)) then
         call set_error(status, STATUS_USAGE, "--adhesion needs --approach (displacement control)")
         return
      end if
      m = size(options%approaches)
      if (m == 0) then
         call set_error(status, STATUS_USAGE, "--adhesion needs --approach (displacement control)")
         return
      end if
      if (law /= "none" .and. .not. (options%work >= 0 .and. options%range > 0)) then
         call set_error(status, STATUS_USAGE, "--adhesion needs --work W >= 0 (J/m^2) and --range R > 0 (nm)")
         return
      end if
      np = problem%np
      area = problem%pixel**2
      res%estimated_peak_bytes = gap_solver_storage_bytes(np, m, options%boundary == "periodic", options%plastic)
      call refuse_beyond_memory("cg --approach (gap variables): NP = "//int_str(np), res%estimated_peak_bytes, &
         options%memory_available, status)
      if (status%code /= 0) return
      g0 = initial_gap_map(problem%lower, problem%upper)
      call make_fourier_grid(grid, problem, options%boundary == "periodic", status)
      if (status%code /= 0) return
      allocate(res%states(m), x(grid%m, grid%m), g(np, np), force(np, np), plastic(np, np), cap(np, np))
      cap = .false.
      x = 0
      ! The plastic cap: a pixel's force at most H d^2; its plastic displacement (nm) is
      ! permanent and raises its initial gap for the rest of the path.
      plastic = 0
      fmax = huge(1.0_dp)
      if (options%plastic) then
         fmax = options%hardness*area
         allocate(res%step_plastic(0))
      end if
      previous_contacts = -1
      last = 0
      do k = 1, m
         call wall_clock(t0)
         associate(st => res%states(k), a => options%approaches(k))
         ! Quasi-static continuation: from the last approach in substeps of at most half
         ! the range, so that no step jumps over the law's reach (the first approach from
         ! the undeformed surfaces).
         nsub = 1
         if (k > 1 .and. law /= "none") nsub = min(MAX_SUBSTEPS, max(1, ceiling(abs(a - last)/(options%range/2))))
         st%iterations = 0
         do sub = 1, nsub
            target = a
            if (sub < nsub) target = last + (a - last)*real(sub, dp)/nsub
            call adhesive_cg(grid, g0 + plastic, target, law, options%work, options%range, area, fmax, &
               options%cg%tol, options%cg%max_iterations, x, g, force, cap, iterations, st%residual, status, observer)
            st%iterations = st%iterations + iterations
            if (status%code /= 0) exit
            ! A capped pixel carries H d^2 by the law (its residual, K x + mu - fmax, is
            ! within the tolerance): exactly, so that no pressure above H is reported.
            if (options%plastic) where (cap) force = fmax
            ! Return mapping: a pixel that yielded keeps its interpenetration as plastic
            ! displacement, and its gap (of the deformed surfaces) is 0.
            if (options%plastic) then
               plastic = plastic + max(-g, 0.0_dp)
               g = max(g, 0.0_dp)
            end if
         end do
         if (status%code /= 0) exit
         last = a
         call wall_clock(t1)
         st%reached = .true.
         st%approach = a
         st%load = sum(force)
         call gather_contacts(st, g == 0, force)
         st%attractive = count(g > 0 .and. g < options%range)
         st%attractive_load = sum(force, mask=g > 0)
         st%mean_gap = sum(g)/real(np, dp)**2
         st%max_pressure = 0
         if (st%contacts > 0) st%max_pressure = maxval(force, mask=g == 0)/area
         st%n_above_hardness = count(force/area > options%hardness)
         st%gap = g
         if (options%plastic) then
            ! The pixels at the cap now, and the plastic displacement of the whole path.
            st%n_plastic = count(cap)
            st%plastic_volume = sum(plastic)*area
            st%plastic = plastic
            res%step_plastic = [res%step_plastic, st%n_plastic]
         end if
         ! A contact set that appears from none, or vanishes, between two approaches is a
         ! jump (into contact, or pull-off): the state left its branch.
         st%jump = 0
         if (previous_contacts == 0 .and. st%contacts > 0) st%jump = 1
         if (previous_contacts > 0 .and. st%contacts == 0) st%jump = -1
         previous_contacts = st%contacts
         call append_step(res, st%contacts, st%n_above_hardness, st%load, a, t1 - t0)
         call observer%progress(k, st%contacts, st%load, t1 - tstart)
         if (k == m) then
            res%contact_i = st%i
            res%contact_j = st%j
            res%contact_step = [(k, i = 1, st%contacts)]
            res%contact_force = st%force
            res%reported_load = st%load
         end if
         end associate
      end do
      call free_fourier_grid(grid)
      res%stop_reason = STOP_LOADS
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart
      if (status%code /= 0) return
      do k = 1, m
         if (res%states(k)%residual > options%cg%tol) then
            call set_error(status, STATUS_NUMERICAL, "adhesion: approach "//format_real(options%approaches(k))// &
               " nm: residual "//sig_str(res%states(k)%residual, 2)//" after "// &
               int_str(res%states(k)%iterations)//" iterations, above --tol "//sig_str(options%cg%tol, 2)// &
               " (raise --max-iterations, or refine the pixel: adhesion_convexity in the summary)")
            return
         end if
      end do
   end subroutine solve_adhesive

   !> The transform grid (M = 2 NP on the free half-space, NP on a periodic cell) and the
   !> spectra of C = c (I * .) + s and of K = C^-1 (on a periodic cell both 0 at zero
   !> frequency: the mean gap is a constraint, adhesive_cg).
   subroutine make_fourier_grid(grid, problem, periodic, status)
      type(fourier_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      logical, intent(in) :: periodic
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: table(:, :)
      real(dp) :: c, s
      integer :: np, m, p, q, i, j, threads
      np = problem%np
      m = merge(np, 2*np, periodic)
      grid%np = np
      grid%m = m
      grid%periodic = periodic
      c = surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), problem%pixel)
      s = 3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)
      allocate(table(0:np - 1, 0:np - 1))
      if (periodic) then
         table(:, :) = periodic_offset_table(np)
      else
         table(:, :) = offset_table(np)
      end if
      grid%pixel_compliance = c*table(0, 0) + s
      grid%real_mem = fftw_alloc_real(int(m, c_size_t)**2)
      grid%complex_mem = fftw_alloc_complex(int(m/2 + 1, c_size_t)*int(m, c_size_t))
      call c_f_pointer(grid%real_mem, grid%field, [m, m])
      call c_f_pointer(grid%complex_mem, grid%spectrum, [m/2 + 1, m])
      ! The transforms on OpenMP's threads (FFTW's threaded plans); plans made after
      ! these two are single-threaded again, as the convolution module's blocks expect.
      threads = 1
      !$ threads = omp_get_max_threads()
      if (fftw_init_threads() == 0) threads = 1
      call fftw_plan_with_nthreads(int(threads, c_int))
      grid%forward = fftw_plan_dft_r2c_2d(int(m, c_int), int(m, c_int), grid%field, grid%spectrum, FFTW_ESTIMATE)
      grid%backward = fftw_plan_dft_c2r_2d(int(m, c_int), int(m, c_int), grid%spectrum, grid%field, FFTW_ESTIMATE)
      call fftw_plan_with_nthreads(1_c_int)
      ! The kernel on the transform grid: offsets 0..NP-1 and -(NP-1)..-1 wrapped (free;
      ! offset NP is never reached by two pixels of the grid), or the periodic cell.
      grid%field = 0
      do j = 1, m
         q = j - 1
         if (q > m/2) q = q - m
         do i = 1, m
            p = i - 1
            if (p > m/2) p = p - m
            if (periodic) then
               grid%field(i, j) = table(i - 1, j - 1)
            else if (abs(p) < np .and. abs(q) < np) then
               grid%field(i, j) = table(abs(p), abs(q))
            end if
         end do
      end do
      call fftw_execute_dft_r2c(grid%forward, grid%field, grid%spectrum)
      ! The kernel is even in both offsets: its spectrum is real.
      grid%compliance = c*real(grid%spectrum, dp) + s
      ! A periodic cell: no zero-frequency compliance (the mean gap is a constraint).
      if (periodic) grid%compliance(1, 1) = 1
      if (.not. minval(grid%compliance) > 0) then
         call set_error(status, STATUS_NUMERICAL, "adhesion: the compliance's spectrum on the "// &
            int_str(m)//" x "//int_str(m)//" grid is not positive (smallest "// &
            sig_str(minval(grid%compliance), 3)//" nm/nN)")
         return
      end if
      grid%stiffness = 1/grid%compliance/real(m, dp)**2
      grid%compliance = grid%compliance/real(m, dp)**2
      if (periodic) then
         grid%stiffness(1, 1) = 0
         grid%compliance(1, 1) = 0
      end if
   end subroutine make_fourier_grid

   subroutine free_fourier_grid(grid)
      type(fourier_grid), intent(inout) :: grid
      if (.not. associated(grid%field)) return
      call fftw_destroy_plan(grid%forward)
      call fftw_destroy_plan(grid%backward)
      call fftw_free(grid%real_mem)
      call fftw_free(grid%complex_mem)
      nullify(grid%field, grid%spectrum)
   end subroutine free_fourier_grid

   !> out = L in on the transform grid, L the operator with the (normalised) spectrum
   !> `multiplier` (the compliance or the stiffness).
   subroutine apply_operator(grid, multiplier, in, out)
      type(fourier_grid), intent(inout) :: grid
      real(dp), intent(in) :: multiplier(:, :), in(:, :)
      real(dp), intent(out) :: out(:, :)
      integer :: i, j
      !$omp parallel do private(i)
      do j = 1, grid%m
         do i = 1, grid%m
            grid%field(i, j) = in(i, j)
         end do
      end do
      !$omp end parallel do
      call fftw_execute_dft_r2c(grid%forward, grid%field, grid%spectrum)
      !$omp parallel do private(i)
      do j = 1, grid%m
         do i = 1, grid%m/2 + 1
            grid%spectrum(i, j) = grid%spectrum(i, j)*multiplier(i, j)
         end do
      end do
      !$omp end parallel do
      call fftw_execute_dft_c2r(grid%backward, grid%spectrum, grid%field)
      !$omp parallel do private(i)
      do j = 1, grid%m
         do i = 1, grid%m
            out(i, j) = grid%field(i, j)
         end do
      end do
      !$omp end parallel do
   end subroutine apply_operator

   !> With the plastic cap fmax, by rounds on the capped set as the fixed-load solver's
   !> capped_solve: the capped pixels carry fmax whatever their gap (a constant gradient,
   !> unbounded: below 0 they interpenetrate), the others are solved as above; then the
   !> contacts above fmax join the set and the capped pixels whose gap opened leave it,
   !> until neither happens (at most MAX_ROUNDS).
   !> The constrained conjugate gradients at approach `a` (nm) from the separations x
   !> (nm, transform grid; returned: the solution). Returned besides: the gaps g (nm, the
   !> NP x NP grid, exactly 0 on the contact) and the pixel forces (nN).
   !> On a periodic cell the approach fixes the mean gap, mean g0 - a (the zero-frequency
   !> compliance is left out: a uniform pressure has no finite displacement there), and
   !> the mean force is the constraint's multiplier mu: the gradient is r = K x + mu +
   !> d^2 phi'(g), mu making its mean over the open pixels zero; directions have zero
   !> mean; after a projection the open gaps are shifted back to the mean gap (Rey et al.).
   subroutine adhesive_cg(grid, g0, a, law, work, range, area, fmax, tol, max_iterations, x, g, force, cap, &
         iterations, residual, status, observer)
      type(fourier_grid), intent(inout) :: grid
      !> fmax: the plastic cap H d^2 (nN; huge: none). A pixel may then interpenetrate
      !> (g < 0) carrying fmax: the potential continues below g = 0 as -fmax g / d^2.
      real(dp), intent(in) :: g0(:, :), a, work, range, area, fmax, tol
      character(len=*), intent(in) :: law
      integer, intent(in) :: max_iterations
      real(dp), intent(inout) :: x(:, :)
      real(dp), intent(out) :: g(:, :), force(:, :)
      !> The capped pixels (with the cap): carried from the last state, returned updated.
      logical, intent(inout) :: cap(:, :)
      integer, intent(out) :: iterations
      real(dp), intent(out) :: residual
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), allocatable :: kx(:, :), r(:, :), z(:, :), d(:, :), w(:, :), r_old(:, :), tension(:, :), &
         curvature(:, :)
      logical, allocatable :: free(:, :)
      real(dp) :: rz, rz_old, rzo, rd, beta, curv, adhesive_curv, tau, scale, worst, mu, mean_gap, open_sum, t, cv
      integer :: np, m, round, i, j, open_count, law_code
      logical :: clipped, capped
      logical, allocatable :: join(:, :), leave(:, :)
      np = grid%np
      m = grid%m
      allocate(kx(m, m), r(m, m), z(m, m), d(m, m), w(m, m), r_old(m, m), free(m, m), &
         tension(np, np), curvature(np, np))
      mean_gap = 0
      if (grid%periodic) then
         mean_gap = sum(g0)/real(np, dp)**2 - a
         if (.not. mean_gap > 0) then
            call set_error(status, STATUS_USAGE, "adhesion: the approach "//format_real(a)//" nm closes the "// &
               "periodic cell's mean gap (mean g0 = "//format_real(sum(g0)/real(np, dp)**2)//" nm): full contact")
            return
         end if
      end if
      capped = fmax < huge(1.0_dp)
      if (.not. capped) cap = .false.
      round = 1
      scale = max(maxval(g0) - minval(g0), tiny(1.0_dp))
      g = g0 - a + x(1:np, 1:np)
      call project(g)
      x(1:np, 1:np) = g - g0 + a
      call apply_operator(grid, grid%stiffness, x, kx)
      d = 0
      r_old = 0
      rz_old = 0
      iterations = 0
      law_code = 0
      if (law == "dugdale") law_code = 1
      if (law == "exponential") law_code = 2
      do
         ! The gradient r = K x (+ the adhesive tension, or -fmax on a capped pixel); the
         ! open pixels' sum for a periodic cell's multiplier.
         open_sum = 0
         open_count = 0
         !$omp parallel do private(i, t, cv) reduction(+:open_sum, open_count)
         do j = 1, m
            do i = 1, m
               if (i <= np .and. j <= np) then
                  if (cap(i, j)) then
                     t = -fmax
                     cv = 0
                  else
                     call pixel_tension(law_code, work, range, area, max(g(i, j), 0.0_dp), t, cv)
                  end if
                  curvature(i, j) = cv
                  r(i, j) = kx(i, j) + t
                  if (g(i, j) > 0) then
                     open_sum = open_sum + r(i, j)
                     open_count = open_count + 1
                  end if
               else
                  r(i, j) = kx(i, j)
               end if
            end do
         end do
         !$omp end parallel do
         mu = 0
         if (grid%periodic) then
            if (open_count > 0) then
               mu = -open_sum/open_count
            else
               mu = -sum(r)/real(np, dp)**2
            end if
         end if
         ! The free set, and the largest violation of the conditions, as the gap it would
         ! move on one pixel, over the height range (the fixed-load solver's measure).
         worst = 0
         !$omp parallel do private(i) reduction(max:worst)
         do j = 1, m
            do i = 1, m
               r(i, j) = r(i, j) + mu
               if (i <= np .and. j <= np) then
                  free(i, j) = g(i, j) > 0 .or. r(i, j) < 0 .or. cap(i, j)
               else
                  free(i, j) = .true.
               end if
               if (free(i, j)) then
                  worst = max(worst, abs(r(i, j)))
               else
                  worst = max(worst, -r(i, j))
               end if
            end do
         end do
         !$omp end parallel do
         residual = worst*grid%pixel_compliance/scale
         if (residual <= tol .and. capped) then
            ! A round of the capped set ends: pixels in contact above the cap join it,
            ! capped pixels whose gap opened leave it; converged when neither happens.
            join = .not. cap .and. g == 0 .and. kx(1:np, 1:np) + mu > fmax
            leave = cap .and. g > 0
            if ((any(join) .or. any(leave)) .and. round < MAX_ROUNDS) then
               round = round + 1
               cap = (cap .or. join) .and. .not. leave
               d = 0
               rz_old = 0
               cycle
            end if
         end if
         if (residual <= tol .or. iterations >= max_iterations) exit
         if (observer%stop_requested()) then
            call set_error(status, STATUS_INTERRUPTED, "stopped after "//int_str(iterations)// &
               " iterations at the approach "//format_real(a)//" nm; the cg solver keeps no checkpoint")
            return
         end if
         iterations = iterations + 1
         ! Preconditioned direction on the free set: z = C r there.
         !$omp parallel do private(i)
         do j = 1, m
            do i = 1, m
               if (.not. free(i, j)) r(i, j) = 0
            end do
         end do
         !$omp end parallel do
         call apply_operator(grid, grid%compliance, r, z)
         rz = 0
         rzo = 0
         !$omp parallel do private(i) reduction(+:rz, rzo)
         do j = 1, m
            do i = 1, m
               if (.not. free(i, j)) z(i, j) = 0
               rz = rz + r(i, j)*z(i, j)
               rzo = rzo + z(i, j)*r_old(i, j)
            end do
         end do
         !$omp end parallel do
         beta = 0
         if (rz_old > 0) beta = max(0.0_dp, (rz - rzo)/rz_old)
         call new_direction(beta)
         if (rd >= 0) call new_direction(0.0_dp)
         rz_old = rz
         call apply_operator(grid, grid%stiffness, d, w)
         curv = 0
         adhesive_curv = 0
         !$omp parallel do private(i) reduction(+:curv, adhesive_curv)
         do j = 1, m
            do i = 1, m
               curv = curv + d(i, j)*w(i, j)
               if (i <= np .and. j <= np) adhesive_curv = adhesive_curv + curvature(i, j)*d(i, j)**2
            end do
         end do
         !$omp end parallel do
         if (curv + adhesive_curv > 0.5_dp*curv) curv = curv + adhesive_curv
         if (.not. curv > 0) exit
         tau = -rd/curv
         ! The gaps move with the separations; a contact off the free set keeps g = 0.
         clipped = .false.
         !$omp parallel do private(i) reduction(.or.:clipped)
         do j = 1, m
            do i = 1, m
               x(i, j) = x(i, j) + tau*d(i, j)
               kx(i, j) = kx(i, j) + tau*w(i, j)
               if (i <= np .and. j <= np) then
                  g(i, j) = g(i, j) + tau*d(i, j)
                  clipped = clipped .or. (g(i, j) < 0 .and. .not. cap(i, j))
               end if
            end do
         end do
         !$omp end parallel do
         if (clipped) then
            call project(g)
            x(1:np, 1:np) = g - g0 + a
            call apply_operator(grid, grid%stiffness, x, kx)
         end if
      end do
      ! The answer's forces from a fresh transform of its separations (on a periodic cell
      ! plus the mean force, the multiplier).
      call apply_operator(grid, grid%stiffness, x, kx)
      force = kx(1:np, 1:np) + mu
   contains
      !> g >= 0 off the capped set; on a periodic cell the open gaps then shifted to the
      !> mean gap, and again, until no open gap went below 0.
      subroutine project(gaps)
         real(dp), intent(inout) :: gaps(:, :)
         integer :: pass
         logical :: open(np, np)
         where (.not. cap) gaps = max(gaps, 0.0_dp)
         if (.not. grid%periodic) return
         do pass = 1, 100
            open = gaps > 0 .and. .not. cap
            if (.not. any(open)) exit
            where (open) gaps = gaps + (mean_gap - sum(gaps)/real(np, dp)**2)*real(np, dp)**2/count(open)
            if (.not. any(open .and. gaps < 0)) exit
            where (open .and. gaps < 0) gaps = 0
         end do
      end subroutine project

      !> d = -z + beta d on the free set (0 elsewhere), with zero mean over the free set
      !> on a periodic cell (the mean gap is held); rd = r.d; r_old = r.
      subroutine new_direction(b)
         real(dp), intent(in) :: b
         real(dp) :: total, shift
         integer :: nfree, ii, jj
         total = 0
         nfree = 0
         !$omp parallel do private(ii) reduction(+:total, nfree)
         do jj = 1, m
            do ii = 1, m
               if (free(ii, jj)) then
                  d(ii, jj) = -z(ii, jj) + b*d(ii, jj)
                  total = total + d(ii, jj)
                  nfree = nfree + 1
               else
                  d(ii, jj) = 0
               end if
            end do
         end do
         !$omp end parallel do
         shift = 0
         if (grid%periodic .and. nfree > 0) shift = total/nfree
         rd = 0
         !$omp parallel do private(ii) reduction(+:rd)
         do jj = 1, m
            do ii = 1, m
               if (free(ii, jj)) d(ii, jj) = d(ii, jj) - shift
               rd = rd + r(ii, jj)*d(ii, jj)
               r_old(ii, jj) = r(ii, jj)
            end do
         end do
         !$omp end parallel do
      end subroutine new_direction
   end subroutine adhesive_cg
end module femcod_adhesion
