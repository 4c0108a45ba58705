!> Fixed-load solver (`--solver cg`): at each requested load, the contact forces of the
!> complementarity problem
!>     F >= 0,  g = g0 - A + c (I * F) + s F >= 0,  F g = 0,  sum F = P
!> on the non-padded NP x NP grid (the same composite model as the other solvers: one
!> compliance c = c1 + c2 with the exact Love kernel I, the springs' s = 3/k on the
!> diagonal, one composite gap g0), by the constrained conjugate gradients of Polonsky and
!> Keer (Wear 231, 1999, 206-219). I * F is a zero-padded (2NP)^2 FFT convolution (FFTW,
!> plans made once, femcod_convolution).
!>
!> What makes it fast without changing the answer (each can be switched off, cg_settings):
!> - Nested grids: the first load starts from the solution on grids of NP/2, NP/4, ...
!>   (2 x 2 averages of the gaps, twice the pixel, the same total load), each solved to a
!>   loose tolerance and handed down with every coarse force split equally over its four
!>   pixels. Later loads start from the previous load's forces, scaled (warm start).
!> - One convolution per iteration: the displacements of the new forces are the old ones
!>   minus tau times those of the search direction, which the step needs anyway; only
!>   the pixels the projection changes (forces clipped to zero, overlapping pixels that
!>   enter) need a correction, added directly from the Love table when they are few
!>   (up to `direct_corrections`), by a split of the kernel when more
!>   (femcod_split_correction: far part on a lattice of 8 pixels, exact within a window
!>   of up to 32), and by a fresh convolution only when the split's error bound, summed
!>   since the last fresh one, would exceed the residual (then the directions restart:
!>   the gaps have moved). At NP = 4096, 1 %: 31 -> 6 fresh convolutions, 23.4 ->
!>   18.5 s (doc/performance.md).
!> - Work on the contacts only, where it can be: besides the convolutions one pass over
!>   all pixels each iteration (the displacements' step and the pixels that enter); the
!>   contacts' gaps, the preconditioner, the direction, the step length and the
!>   projection run over a list of the contact pixels, and the load balance is applied
!>   where the values are next written instead of by a pass of its own. At NP = 4096,
!>   1 %: 0.44 -> 0.25 s an iteration, 38 -> 28 s the solve (doc/performance.md). This
!>   one has no switch: it is the same iteration, with its sums taken in another order.
!> - float32 transforms for the search directions, and for the forces' own displacements
!>   while the residual is large (above `single_until`), then double.
!>   Every switch, and the final answer, starts from a fresh double convolution.
!> - A preconditioner: the search direction is the contact gaps filtered by the 13-point
!>   stencil of the inverse Love operator (inverse_kernel_taps, a discrete E*|q|/2).
!>   Overlapping pixels enter with a quarter of the force the preconditioned step gives a
!>   pixel alone, -tau a00 g / 4 (a00 the stencil's centre), where Polonsky and Keer's
!>   unpreconditioned step gives -tau g: without a00 the entering forces are out of scale
!>   with the step and the contact set swings (at NP = 1024, 1 %: to three times its final
!>   size); with all of it, pixels enter too strongly and many leave again (4096^2, 1 %:
!>   52 iterations against 44 with the quarter; cg_settings%entry_scale).
!> - beta by Polak-Ribiere clipped at zero (PR+) rather than Fletcher-Reeves: it restarts
!>   by itself when the contact set has turned the gradient (2048^2: 45 -> 40 iterations
!>   at 1 %, 77 -> 71 at 10 %).
!> - Powell's restart (1977): beta = 0 when |z.g_old| >= 0.2 z.g, successive gradients
!>   far from orthogonal. After the coarse start on large grids the contact set can swing
!>   (NP = 4096, 10 %: from 1.9 to 3.3 million pixels and back, 141 iterations); with the
!>   test it does not (99).
!> - No restart of the conjugate directions when overlapping pixels enter the contact
!>   (Polonsky and Keer restart; `restart_on_entry` brings it back), nor after a fresh
!>   convolution (in the first iterations, when many forces change, that is every
!>   iteration, and the method would be steepest descent).
!>
!> Stopping rule: the relative complementarity residual
!>     r = max( max over contacts |g| , max over the rest max(-g, 0) ) / (max g0 - min g0)
!> (the largest gap violation in units of the height range) below `tol` (default 1e-8),
!> evaluated on displacements from a fresh double-precision convolution of the final
!> forces, with the load balanced to round-off by construction. The residuals reached
!> are returned: max penetration (nm), largest |gap| on contact (nm), load error, r.
!>
!> Error bound of the approach (approach_error_bound): the forces returned are the exact
!> answer for gaps g0 moved by at most eps = max(penetration, |gap| on contact) at every
!> pixel (a backward error), and the exact approach moves by at most eps when g0 does:
!> the stiffness S = (c I + s)^-1 has no positive entry off its diagonal and positive
!> row sums (an M-matrix; test_cg checks both on a dense grid), so the displacements are
!> the least supersolution of the obstacle problem, monotone in the obstacle, and the
!> load, the sum of S times them, is monotone too; moving all of g0 by eps moves the
!> approach by exactly eps.
module femcod_cg
   use, intrinsic :: iso_fortran_env, only: int8
   use femcod_kinds, only: dp, sp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED, STATUS_USAGE
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gap_map
   use femcod_split_correction, only: split_correction, split_setup, split_apply, split_free, split_hand_over
   use femcod_love, only: offset_table, surface_compliance
   use femcod_love_periodic, only: periodic_offset_table
   use femcod_spring, only: spring_stiffness
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, &
      convolution_free, inverse_kernel_taps
   use femcod_contact_result, only: contact_result, load_state, append_step, STOP_LOADS, gather_contacts
   use femcod_solver_options, only: refuse_beyond_memory, contact_options, cg_settings
   use femcod_observer, only: solver_observer
   use femcod_strings, only: int_str, sig_str, format_real
   use femcod_clock, only: wall_clock
   !$ use omp_lib, only: omp_get_max_threads, omp_get_thread_num
   implicit none
   private
   public :: solve_cg, coarse_start_forces, approach_error_bound, cg_storage_bytes

   !> What the CG solver reached at one load.
   type :: cg_residuals
      !> Iterations on the full grid, and on all coarser grids together.
      integer :: iterations = 0, coarse_iterations = 0
      !> Fresh convolutions of the forces on the full grid (when more than
      !> `direct_corrections` forces changed and the kernel split may not take them, at
      !> the switch to double, and for the final check); each iteration convolves its
      !> search direction besides. Corrections by the kernel split.
      integer :: convolutions = 0, split_corrections = 0
      real(dp) :: penetration = 0, contact_gap = 0, load_error = 0, residual = 0
   end type cg_residuals

   !> One grid of the problem: gaps (nm), pixel (nm), compliance c (nm/nN) and spring
   !> compliance s (nm/nN), the Love table and its convolution.
   type :: cg_grid
      integer :: np = 0
      !> The grid is one cell of a periodic surface (periodic table, cyclic convolution).
      logical :: periodic = .false.
      real(dp) :: pixel = 0, c = 0, s = 0, scale = 1
      real(dp), allocatable :: g0(:, :)
      !> The Love table I(0:np-1, 0:np-1) for direct corrections, rounded to float32 (its
      !> double is needed only to set up the convolution; at NP = 4096 the float32 table
      !> is 67 MB); self = I(0, 0), one pixel's own coefficient, in double.
      real(sp), allocatable :: table(:, :)
      real(dp) :: self = 0
      !> Preconditioner taps (inverse_kernel_taps); `preconditioned` false: none.
      logical :: preconditioned = .false.
      real(dp) :: taps(0:2, 0:2) = 0
      type(love_convolution) :: conv
      type(split_correction) :: split
   end type cg_grid

   !> Pixels (i, j) in the order one thread found them (pixels entering the contacts).
   type :: pixel_list
      integer :: n = 0
      integer, allocatable :: ij(:, :)
   end type pixel_list

contains

   !> The cg solver's storage at its largest (bytes), from the arrays it allocates per
   !> pixel of the NP x NP grid: the forces, the grid's gaps and Love table (8 bytes each);
   !> the kernel's spectrum, complex on (M/2 + 1) x NP with M = 2 NP free or NP periodic
   !> (16 or 8 bytes a pixel), and its half-plane of real coefficients (8 or 2); the
   !> iteration's w, t, the stencil's padded copy, the residual and the last gradient (8
   !> each), its contact flags (4) and list (8); each requested state's gap map (8). With
   !> the plastic cap: the deck's gaps, the capped flags, the capped rounds' force, field
   !> and gap maps (8 + 4 + 24), and each state's plastic map (8). The nested coarse grids
   !> (a third of this) come and go before the fine grid's iteration.
   pure function cg_storage_bytes(np, nstates, periodic, plastic) result(bytes)
      integer, intent(in) :: np, nstates
      logical, intent(in) :: periodic, plastic
      integer(i8) :: bytes, n2, per_pixel
      n2 = int(np, i8)**2
      per_pixel = 3*8 + merge(8, 16, periodic) + merge(2, 8, periodic) + 5*8 + 4 + 8 + 8*nstates
      if (plastic) per_pixel = per_pixel + 8 + 4 + 24 + 8*nstates
      bytes = n2*per_pixel
   end function cg_storage_bytes

   !> The approach (nm) of a fixed-load answer lies within this many nm of the exact
   !> answer of the discrete problem (module header): the largest gap violation eps =
   !> max(penetration, contact_gap) (nm), plus the load error's share, load_error times
   !> the approach (a relative load error e moves the approach by at most e times it while
   !> the load-approach curve is convex from first touch, the contact stiffness growing
   !> with the contact; e is round-off, 1e-16, by construction).
   pure real(dp) function approach_error_bound(penetration, contact_gap, load_error, approach) result(bound)
      real(dp), intent(in) :: penetration, contact_gap, load_error, approach
      bound = max(penetration, contact_gap) + load_error*abs(approach)
   end function approach_error_bound

   !> Solve at every requested load (ascending order of computation; results in the
   !> order given, with the residuals reached in each load state). A load whose residual
   !> stays above options%cg%tol after options%cg%max_iterations is a numerical failure.
   subroutine solve_cg(problem, options, res, status, observer)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      !> Told of every load solved (progress).
      class(solver_observer), intent(inout) :: observer
      type(cg_residuals), allocatable :: report(:)
      type(cg_grid) :: fine
      real(dp), allocatable :: p(:, :), g0(:, :), targets(:)
      logical, allocatable :: capped(:, :)
      integer, allocatable :: order(:)
      real(dp) :: load, tstart, t0, t1, approach
      integer :: np, k, kk, m, i, j
      logical :: by_approach
      call wall_clock(tstart)
      associate(how => options%cg, tol => options%cg%tol, max_iterations => options%cg%max_iterations)
      np = problem%np
      ! Displacement control (--approach): the targets are approaches, the loads the answers.
      by_approach = .false.
      if (allocated(options%approaches)) by_approach = size(options%approaches) > 0
      if (by_approach) then
         targets = options%approaches
      else
         targets = options%loads
      end if
      m = size(targets)
      allocate(report(m), res%states(m))
      if (by_approach) then
         res%states%approach = targets
         res%states%load = 0
      else
         res%states%load = targets
      end if
      if (m == 0) then
         call set_error(status, STATUS_USAGE, "cg: --solver cg needs --loads or --approach")
         return
      end if
      res%estimated_peak_bytes = cg_storage_bytes(np, m, options%boundary == "periodic", options%plastic)
      call refuse_beyond_memory("cg: NP = "//int_str(np), res%estimated_peak_bytes, options%memory_available, status)
      if (status%code /= 0) return
      call make_grid(fine, initial_gap_map(problem%lower, problem%upper), problem, &
         problem%pixel, how, options%boundary == "periodic")
      ! A periodic cell is in full contact when the approach (the fall of the mean gap)
      ! reaches the mean initial gap; there any load above the full-contact load gives
      ! that approach, and beyond it none does (the elastic displacements have no mean).
      if (by_approach .and. fine%periodic .and. .not. options%plastic) then
         if (maxval(targets) >= sum(fine%g0)/real(np, dp)**2) then
            call set_error(status, STATUS_USAGE, "--approach "//format_real(maxval(targets))//" nm reaches the "// &
               "periodic cell's mean gap ("//format_real(sum(fine%g0)/real(np, dp)**2)//" nm): full contact, "// &
               "where the approach no longer determines the load; give --loads for loads beyond full contact")
            call convolution_free(fine%conv)
            call split_free(fine%split)
            return
         end if
      end if
      allocate(p(np, np))
      if (options%plastic) then
         g0 = fine%g0
         allocate(res%step_plastic(0), capped(np, np))
         capped = .false.
      end if
      ! Ascending loads, each warm-started from the last.
      allocate(order(m))
      order = [(k, k = 1, m)]
      do k = 2, m
         kk = k
         do while (kk > 1)
            if (targets(order(kk - 1)) <= targets(order(kk))) exit
            order([kk - 1, kk]) = order([kk, kk - 1])
            kk = kk - 1
         end do
      end do
      p = 0
      approach = 0
      do kk = 1, m
         k = order(kk)
         call wall_clock(t0)
         if (by_approach) then
            call find_load(targets(k), k)
            load = res%states(k)%load
         else
            load = targets(k)
            call solve_load(load, k)
         end if
         if (status%code /= 0) exit
         call wall_clock(t1)
         ! The state at this load.
         associate(st => res%states(k))
            st%reached = .true.
            st%approach = approach
            st%iterations = report(k)%iterations
            st%residual = report(k)%residual
            st%penetration = report(k)%penetration
            st%contact_gap = report(k)%contact_gap
            st%load_error = report(k)%load_error
            if (.not. (by_approach .or. options%plastic .or. options%boundary == "periodic" .or. &
               how%kernel_radius > 0)) st%approach_bound = approach_error_bound(st%penetration, &
               st%contact_gap, st%load_error, st%approach)
            st%coarse_iterations = report(k)%coarse_iterations
            st%convolutions = report(k)%convolutions
            st%split_corrections = report(k)%split_corrections
            st%contacts = count(p > 0)
            st%max_pressure = maxval(p)/problem%pixel**2
            st%n_above_hardness = count(p/problem%pixel**2 > options%hardness)
            if (options%plastic) then
               st%n_plastic = count(capped)
               st%plastic_volume = sum(st%plastic)*problem%pixel**2
            end if
            call gather_contacts(st, p > 0, p)
            call append_step(res, st%contacts, st%n_above_hardness, load, st%approach, t1 - t0)
            if (options%plastic) res%step_plastic = [res%step_plastic, st%n_plastic]
            call observer%progress(kk, st%contacts, load, t1 - tstart)
            if (targets(k) == maxval(targets)) then
               res%contact_i = st%i
               res%contact_j = st%j
               res%contact_step = [(kk, i = 1, st%contacts)]
               res%contact_force = st%force
               res%reported_load = load
            end if
         end associate
      end do
      call convolution_free(fine%conv)
      call split_free(fine%split)
      res%stop_reason = STOP_LOADS
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart
      if (status%code /= 0) return
      do k = 1, m
         if (report(k)%residual > tol) then
            call set_error(status, STATUS_NUMERICAL, "cg: "//trim(merge("approach", "load    ", by_approach))//" "// &
               format_real(targets(k))//trim(merge(" nm", " nN", by_approach))//": residual "// &
               sig_str(report(k)%residual, 2)//" after "//int_str(report(k)%iterations)// &
               " iterations, above --tol "//sig_str(tol, 2)//" (raise --max-iterations)")
            return
         end if
      end do
      end associate
   contains
      !> The state at `load` (nN) into res%states(k): the forces p (warm start: the last
      !> solution's, scaled by the solver to the load) and the approach.
      subroutine solve_load(load, k)
         real(dp), intent(in) :: load
         integer, intent(in) :: k
         associate(how => options%cg)
         if (load <= 0) then
            p = 0
            approach = -minval(fine%g0)
            if (options%plastic) capped = .false.
         else if (options%plastic) then
            call capped_solve(fine, problem, g0, load, options%hardness*problem%pixel**2, how, p, capped, approach, &
               report(k), res%states(k), status, observer)
         else
            if (.not. sum(p) > 0) then
               if (how%nested) then
                  call nested_start(fine, problem, load, how, p, report(k), status, observer)
               else
                  call first_guess(fine, load, p)
               end if
               if (status%code /= 0) return
            end if
            call constrained_cg(fine, load, how%tol, how%max_iterations, how, p, approach, report(k), status, &
               observer, res%states(k)%gap)
         end if
         end associate
      end subroutine solve_load

      !> Displacement control: the load at which the approach is `target` (nm), by the
      !> Illinois variant of regula falsi on A(P) - target (A increases with P), each
      !> A(P) a fixed-load solve warm-started from the last; to |A - target| <= tol times
      !> the height range, the fixed-load solver's own accuracy. At or below first touch
      !> (target <= 0) the state has no load and no contact. The load is the answer
      !> (res%states(k)%load); report(k) counts the iterations of every solve.
      subroutine find_load(target, k)
         real(dp), intent(in) :: target
         integer, intent(in) :: k
         integer, parameter :: MAX_SOLVES = 100
         real(dp) :: lo, alo, hi, ahi, trial, accuracy
         integer :: solve, side
         accuracy = options%cg%tol*fine%scale
         if (target <= 0) then
            res%states(k)%load = 0
            call solve_load(0.0_dp, k)
            approach = target
            return
         end if
         lo = 0
         alo = 0
         hi = -1
         ahi = 0
         side = 0
         ! First trial: the last solution's load scaled as Hertz (P ~ A^1.5), or one
         ! pixel's stiffness.
         if (sum(p) > 0 .and. approach > 0) then
            trial = sum(p)*(target/approach)**1.5_dp
         else
            trial = target/(fine%c*fine%self + fine%s)
         end if
         do solve = 1, MAX_SOLVES
            call solve_load(trial, k)
            if (status%code /= 0) return
            if (abs(approach - target) <= accuracy) exit
            ! Illinois: an end kept twice in a row has its residual halved.
            if (approach < target) then
               lo = trial
               alo = approach
               if (side == -1) ahi = target + (ahi - target)/2
               side = -1
            else
               hi = trial
               ahi = approach
               if (side == 1) alo = target - (target - alo)/2
               side = 1
            end if
            if (hi < 0) then
               ! No bracket yet: the load grows as Hertz would have it, at least doubled.
               trial = lo*max(2.0_dp, (target/max(alo, tiny(1.0_dp)))**1.5_dp)
            else
               trial = lo + (hi - lo)*(target - alo)/(ahi - alo)
               if (.not. (trial > lo .and. trial < hi)) trial = (lo + hi)/2
            end if
         end do
         if (solve > MAX_SOLVES) then
            call set_error(status, STATUS_NUMERICAL, "cg --approach: no load found for the approach "// &
               format_real(target)//" nm in "//int_str(MAX_SOLVES)//" solves")
            return
         end if
         res%states(k)%load = trial
      end subroutine find_load
   end subroutine solve_cg

   !> The elastic-perfectly-plastic interface at one load: 0 <= F <= fmax = H d^2 per
   !> pixel, with
   !>     F = 0: g >= 0,   0 < F < fmax: g = 0,   F = fmax: g <= 0 (plastic, -g its
   !>     plastic displacement),   sum F = P.
   !> By rounds on the plastic set: the capped pixels carry fmax and are taken out of the
   !> elastic problem (their displacements c I * fmax become part of the others' gaps),
   !> which constrained_cg solves for the rest at the load left, P - n_capped fmax; then
   !> the pixels above fmax join the set and the capped pixels whose gap opened (beyond
   !> tol of the height range) leave it, until neither happens. A set only grows by
   !> pixels that carried more than fmax in a solution of the whole load, so the load left
   !> stays positive. Without a capped pixel this is the elastic solve, bit for bit.
   !> Returned: the forces (fmax on the capped pixels), the approach, the plastic set,
   !> and in `state` the gap map (0 on the elastic contacts, minus the plastic
   !> displacement on the capped ones) and the plastic displacement map.
   subroutine capped_solve(grid, problem, g0, load, fmax, how, p, capped, approach, rep, state, status, observer)
      type(cg_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      !> The deck's gaps (nm); grid%g0 is restored to them on return.
      real(dp), intent(in) :: g0(:, :)
      real(dp), intent(in) :: load, fmax
      type(cg_settings), intent(in) :: how
      real(dp), intent(inout) :: p(:, :)
      logical, intent(inout) :: capped(:, :)
      real(dp), intent(out) :: approach
      type(cg_residuals), intent(inout) :: rep
      type(load_state), intent(inout) :: state
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      !> The gap that takes a capped pixel out of the elastic problem (it never touches).
      real(dp), parameter :: EXCLUDED = 1.0e30_dp
      integer, parameter :: MAX_ROUNDS = 200
      real(dp), allocatable :: force(:, :), w(:, :), gap(:, :)
      logical, allocatable :: grow(:, :), release(:, :)
      real(dp) :: left
      integer :: round, ncap
      allocate(force(size(p, 1), size(p, 2)), w(size(p, 1), size(p, 2)))
      do round = 1, MAX_ROUNDS
         ncap = count(capped)
         if (ncap > 0) then
            force = merge(fmax, 0.0_dp, capped)
            call convolution_apply(grid%conv, force, w, grid%c)
            grid%g0 = merge(EXCLUDED, g0 + w, capped)
            where (capped) p = 0
         else
            grid%g0 = g0
         end if
         left = load - ncap*fmax
         if (.not. sum(p) > 0) then
            if (how%nested .and. ncap == 0) then
               call nested_start(grid, problem, left, how, p, rep, status, observer)
            else
               call first_guess(grid, left, p)
            end if
            if (status%code /= 0) exit
         end if
         call constrained_cg(grid, left, how%tol, how%max_iterations, how, p, approach, rep, status, observer, &
            state%gap)
         if (status%code /= 0) exit
         ! The gaps of all forces together, from one fresh double-precision convolution.
         force = merge(fmax, p, capped)
         call convolution_apply(grid%conv, force, w, grid%c)
         gap = g0 - approach + w + grid%s*force
         grow = .not. capped .and. p > fmax
         release = capped .and. gap > how%tol*grid%scale
         if (.not. (any(grow) .or. any(release))) exit
         ! A released pixel starts from the force it had.
         where (release) p = fmax
         capped = (capped .or. grow) .and. .not. release
      end do
      grid%g0 = g0
      state%plastic_rounds = min(round, MAX_ROUNDS)
      if (status%code /= 0) return
      if (round > MAX_ROUNDS) then
         call set_error(status, STATUS_NUMERICAL, "cg --plastic: the plastic set did not settle in "// &
            int_str(MAX_ROUNDS)//" rounds at load "//format_real(load)//" nN")
         return
      end if
      p = merge(fmax, p, capped)
      if (allocated(state%plastic)) deallocate(state%plastic)
      allocate(state%plastic(size(p, 1), size(p, 2)))
      state%plastic = 0
      if (any(capped)) then
         state%gap = merge(0.0_dp, gap, p > 0 .and. .not. capped)
         where (capped) state%plastic = max(-gap, 0.0_dp)
      end if
   end subroutine capped_solve

   !> A grid for gaps g0 (nm) with pixel size `pixel` (nm) and the deck's materials, one
   !> cell of a periodic surface when `periodic`.
   subroutine make_grid(grid, g0, problem, pixel, how, periodic)
      type(cg_grid), intent(inout) :: grid
      real(dp), intent(in) :: g0(:, :)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: pixel
      type(cg_settings), intent(in) :: how
      logical, intent(in) :: periodic
      real(dp), allocatable :: table(:, :)
      grid%np = size(g0, 1)
      grid%periodic = periodic
      grid%pixel = pixel
      grid%g0 = g0
      grid%c = surface_compliance(problem%young(1), problem%poisson(1), pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), pixel)
      grid%s = 3/spring_stiffness(problem%young(3), problem%poisson(3), pixel, pixel)
      grid%scale = max(maxval(g0) - minval(g0), tiny(1.0_dp))
      allocate(table(0:grid%np - 1, 0:grid%np - 1))
      if (periodic) then
         table(:, :) = periodic_offset_table(grid%np)
      else
         table(:, :) = offset_table(grid%np)
      end if
      if (how%kernel_radius > 0) call truncate_table(table, how%kernel_radius*problem%pixel/pixel)
      call convolution_setup(grid%conv, table, how%single_until > 0, how%measure_plans, periodic)
      grid%self = table(0, 0)
      allocate(grid%table(0:grid%np - 1, 0:grid%np - 1))
      grid%table(:, :) = real(table, sp)
      if (how%precondition) call inverse_kernel_taps(grid%conv, grid%taps, grid%preconditioned)
   end subroutine make_grid

   !> The kernel truncated: entries at offsets beyond `radius` pixels set to 0 (--kernel-
   !> radius, in the finest grid's pixels; a coarser grid's radius is scaled to its pixel).
   pure subroutine truncate_table(table, radius)
      real(dp), intent(inout) :: table(0:, 0:)
      real(dp), intent(in) :: radius
      integer :: p, q
      do q = 0, size(table, 2) - 1
         do p = 0, size(table, 1) - 1
            if (real(p, dp)**2 + real(q, dp)**2 > radius**2) table(p, q) = 0
         end do
      end do
   end subroutine truncate_table

   !> Start: the load spread over the pixels within a tenth of the height range of the
   !> first touch.
   subroutine first_guess(grid, total_load, p)
      type(cg_grid), intent(in) :: grid
      real(dp), intent(in) :: total_load
      real(dp), intent(out) :: p(:, :)
      where (grid%g0 <= minval(grid%g0) + 0.1_dp*grid%scale)
         p = 1
      elsewhere
         p = 0
      end where
      p = p*(total_load/sum(p))
   end subroutine first_guess

   !> The first load's start from nested grids: halve while the side stays even and at
   !> least 2 * coarsest; solve the coarsest from the first guess, then each finer grid
   !> from the coarser solution, to coarse_tol; return the forces on the finest grid.
   recursive subroutine nested_start(grid, problem, total_load, how, p, rep, status, observer)
      type(cg_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: total_load
      type(cg_settings), intent(in) :: how
      real(dp), intent(out) :: p(:, :)
      type(cg_residuals), intent(inout) :: rep
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(cg_grid) :: coarse
      type(cg_residuals) :: coarse_rep
      real(dp), allocatable :: pc(:, :)
      real(dp) :: approach
      integer :: n, i, j
      n = grid%np
      if (mod(n, 2) /= 0 .or. n < 2*how%coarsest) then
         call first_guess(grid, total_load, p)
         return
      end if
      n = n/2
      call make_grid(coarse, (grid%g0(1::2, 1::2) + grid%g0(2::2, 1::2) + grid%g0(1::2, 2::2) + &
         grid%g0(2::2, 2::2))/4, problem, 2*grid%pixel, how, grid%periodic)
      allocate(pc(n, n))
      call nested_start(coarse, problem, total_load, how, pc, rep, status, observer)
      if (status%code == 0) call constrained_cg(coarse, total_load, how%coarse_tol, 10000, how, pc, approach, &
         coarse_rep, status, observer)
      call convolution_free(coarse%conv)
      call split_hand_over(coarse%split, grid%split)
      call split_free(coarse%split)
      if (status%code /= 0) return
      rep%coarse_iterations = rep%coarse_iterations + coarse_rep%iterations + coarse_rep%coarse_iterations
      do j = 1, n
         do i = 1, n
            p(2*i - 1:2*i, 2*j - 1:2*j) = pc(i, j)/4
         end do
      end do
   end subroutine nested_start

   !> The forces (nN) at total load P (nN) on a grid of gaps g0 (nm) and pixel `pixel`
   !> (nm), free surface, solved from its own nested start to how%coarse_tol: the start
   !> that the distributed solver (femcod-mpi) hands down to its finer grid, as
   !> nested_start does here. `iterations`: on this grid and all coarser ones.
   subroutine coarse_start_forces(g0, problem, pixel, total_load, how, p, iterations, status, observer)
      real(dp), intent(in) :: g0(:, :)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: pixel, total_load
      type(cg_settings), intent(in) :: how
      real(dp), intent(out) :: p(:, :)
      integer, intent(out) :: iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(cg_grid) :: grid
      type(cg_residuals) :: rep
      real(dp) :: approach
      call make_grid(grid, g0, problem, pixel, how, .false.)
      if (how%nested) then
         call nested_start(grid, problem, total_load, how, p, rep, status, observer)
      else
         call first_guess(grid, total_load, p)
      end if
      if (status%code == 0) call constrained_cg(grid, total_load, how%coarse_tol, 10000, how, p, approach, rep, &
         status, observer)
      call convolution_free(grid%conv)
      call split_free(grid%split)
      iterations = rep%iterations + rep%coarse_iterations
   end subroutine coarse_start_forces

   !> (femcod-mpi's distributed_cg, mpi/src/femcod_mpi_cg.f90, follows the same iteration
   !> on all pixels of each rank's slab, with the sums over MPI ranks: a change to the
   !> method here belongs there too.)
   !> Polonsky-Keer constrained CG on `grid` at total load P from the forces p (nN, any
   !> positive start; returned: the solution). `approach` (nm) is the mean gap of the
   !> contact pixels before the rigid shift, i.e. the approach from first touch.
   !>
   !> Only two things need every pixel in each iteration: the convolution, and one pass
   !> that moves the displacements by the step and lets overlapping pixels enter. All else
   !> (the contacts' gaps, the preconditioner, the direction, the step length, the
   !> projection) runs over the list of contact pixels, which is 1 to 10 % of the grid at
   !> the loads users ask for: at NP = 4096 the passes over all pixels moved 3.4 GB a
   !> iteration before, 0.5 GB now. The penetration off the contacts, which needs every
   !> pixel, is evaluated only when the contacts' own residual is below a threshold the
   !> test compares with (tol, single_until, or at the last iteration): above it the
   !> residual is above the threshold whatever the penetration, so every decision is the
   !> one the full residual would give.
   subroutine constrained_cg(grid, total_load, tol, max_iterations, how, p, approach, rep, status, observer, final_gap)
      type(cg_grid), intent(inout) :: grid
      real(dp), intent(in) :: total_load, tol
      integer, intent(in) :: max_iterations
      type(cg_settings), intent(in) :: how
      real(dp), intent(inout) :: p(:, :)
      real(dp), intent(out) :: approach
      type(cg_residuals), intent(inout) :: rep
      type(status_type), intent(inout) :: status
      !> Asked every iteration whether to stop (a stop signal).
      class(solver_observer), intent(inout) :: observer
      !> The gap (nm) of the solution, from the last fresh double-precision convolution,
      !> 0 at the contacts: the gap map of this load (solvers/femcod_maps), without a
      !> convolution of its own.
      real(dp), allocatable, intent(out), optional :: final_gap(:, :)
      ! No array of the gaps: they are g0 + alpha (w + s p) - gbar, formed where they are
      ! used, and gm keeps them in float32 on the contacts (zero elsewhere, two pixels of
      ! padding for the stencil) for the direction and its step, which the gaps recomputed
      ! in double each iteration correct; nor of the preconditioned gaps z (stencil_at,
      ! formed twice). r, the displacements of the direction, is float32 (r32) when the
      ! transform making it is. At NP = 4096 each NP x NP array is 134 MB in double.
      real(dp), allocatable :: w(:, :), t(:, :), r(:, :)
      real(sp), allocatable :: gm(:, :), r32(:, :)
      !> The contact pixels (p > 0) as (i, j), column by column, and on the grid as 1 in
      !> `touching` (one byte a pixel, for the pass over all pixels).
      integer, allocatable :: contact(:, :)
      integer(int8), allocatable :: touching(:, :)
      !> The previous gaps at the contacts, in the order of `contact`, for beta and
      !> Powell's test (float32 is enough). A pixel that enters keeps its gap in gm until
      !> the next iteration reads it here.
      real(sp), allocatable :: g_old(:)
      !> The pixels each thread found entering in one step, in column order.
      type(pixel_list), allocatable :: entering(:)
      integer, allocatable :: changed(:, :)
      real(dp), allocatable :: delta(:)
      real(dp) :: c, s, gbar, big_g, big_g_old, beta, num, den, tau, rt, rsum, tsum, rbar, psum, psum_in, residual, &
         contact_gap, penetration, alpha, pn, lin, entry, zbar, cross, gij, threshold
      integer :: np, i, j, q, it, nc, nchanged, limit, split_limit, capacity, reach, thread, threads
      !> The error bound (nm) of the split corrections since the last fresh convolution.
      real(dp) :: split_error, bound
      logical :: restart, single, fresh, fresh_double, stalled, keep_old, kept_old
      np = grid%np
      c = grid%c
      s = grid%s
      limit = max(how%direct_corrections, 0)
      ! The kernel split takes up to split_limit changes: the budget with the smallest
      ! window (one lattice cell); the full kernel only (not periodic, not truncated).
      split_limit = 0
      if (how%split_radius >= how%split_cell .and. how%split_cell >= 1 .and. .not. grid%periodic .and. &
         .not. how%kernel_radius > 0) &
         split_limit = int(min(how%split_budget*real(np, dp)**2/real(2*how%split_cell + 1, dp)**2, real(np, dp)**2, &
         real(huge(1)/2, dp)))
      capacity = max(limit, split_limit)
      threads = 1
      !$ threads = omp_get_max_threads()
      allocate(w(np, np), t(np, np), gm(-1:np + 2, -1:np + 2), changed(2, capacity), delta(capacity), touching(np, np), &
         entering(0:threads - 1))
      if (how%single_until > 0) then
         allocate(r32(np, np))
      else
         allocate(r(np, np))
      end if
      gm = 0
      ! The previous gradient, for Polak-Ribiere's beta and for Powell's restart test.
      keep_old = how%polak_ribiere .or. how%powell_restart > 0
      kept_old = .false.
      ! Overlapping pixels enter with a share (entry_scale) of the preconditioned step's
      ! force for a lone pixel.
      entry = 1
      if (grid%preconditioned) entry = how%entry_scale*grid%taps(0, 0)
      ! The start's contacts; the direction is zero off the contacts throughout.
      !$omp parallel do private(i)
      do j = 1, np
         do i = 1, np
            touching(i, j) = merge(1_int8, 0_int8, p(i, j) > 0)
            t(i, j) = 0
         end do
      end do
      call list_contacts()
      ! The load balance: the forces and displacements are alpha times the stored p and w,
      ! until the next step writes them scaled (and at the end).
      alpha = total_load/sum(p)
      single = how%single_until > 0
      fresh = .true.
      split_error = 0
      restart = .true.
      big_g_old = 1
      it = 0
      zbar = 0
      fresh_double = .false.
      stalled = .false.
      penetration = 0
      do
         if (observer%stop_requested()) then
            call set_error(status, STATUS_INTERRUPTED, "stopped after "//int_str(it)//" iterations on the "// &
               int_str(np)//" x "//int_str(np)//" grid; the cg solver keeps no checkpoint")
            return
         end if
         if (fresh) then
            call displacements(p, w)
            split_error = 0
            fresh = .false.
            stalled = .false.
         end if
         nc = size(contact, 2)
         if (nc == 0) then
            call set_error(status, STATUS_NUMERICAL, "cg: all forces vanished")
            return
         end if
         ! The contacts' mean gap.
         gbar = 0
         !$omp parallel do private(i, j) reduction(+:gbar)
         do q = 1, nc
            i = contact(1, q)
            j = contact(2, q)
            gbar = gbar + (grid%g0(i, j) + alpha*(w(i, j) + s*p(i, j)))
         end do
         gbar = gbar/nc
         approach = gbar
         ! The contacts' residual, the search direction's norm, and their gaps for the
         ! preconditioner; the previous gaps taken from gm first, once an iteration.
         if (keep_old .and. .not. kept_old) then
            if (allocated(g_old)) deallocate(g_old)
            allocate(g_old(nc))
         end if
         big_g = 0
         cross = 0
         contact_gap = 0
         !$omp parallel do private(i, j, gij) reduction(+:big_g, cross) reduction(max:contact_gap)
         do q = 1, nc
            i = contact(1, q)
            j = contact(2, q)
            gij = grid%g0(i, j) + alpha*(w(i, j) + s*p(i, j)) - gbar
            if (keep_old .and. .not. kept_old) g_old(q) = gm(i, j)
            big_g = big_g + gij**2
            if (keep_old .and. .not. grid%preconditioned) cross = cross + gij*real(g_old(q), dp)
            contact_gap = max(contact_gap, abs(gij))
            gm(i, j) = real(gij, sp)
         end do
         kept_old = keep_old
         ! The penetration off the contacts, where a decision depends on it.
         threshold = tol
         if (single) threshold = max(tol, how%single_until)
         if (contact_gap/grid%scale < threshold .or. it >= max_iterations .or. stalled) then
            penetration = deepest_overlap()
         else
            penetration = 0
         end if
         residual = max(contact_gap, penetration)/grid%scale
         if (residual < tol .or. it >= max_iterations .or. stalled) then
            ! Accept only on displacements from a fresh double-precision convolution.
            if (.not. fresh_double) then
               single = .false.
               fresh = .true.
               cycle
            end if
            exit
         end if
         ! The split corrections' error bound stays below split_tolerance times the
         ! residual: once the residual has fallen to it, the displacements afresh and new
         ! directions.
         if (split_error > how%split_tolerance*residual*grid%scale) then
            fresh = .true.
            restart = .true.
            cycle
         end if
         if (single .and. residual < how%single_until) then
            single = .false.
            fresh = .true.
            cycle
         end if
         if (grid%preconditioned) call precondition(big_g, zbar, cross)
         it = it + 1
         if (how%powell_restart > 0 .and. abs(cross) >= how%powell_restart*big_g) restart = .true.
         if (restart .or. .not. big_g_old > 0) then
            beta = 0
         else if (how%polak_ribiere) then
            beta = max(0.0_dp, (big_g - cross)/big_g_old)
         else
            beta = big_g/big_g_old
         end if
         big_g_old = big_g
         num = 0
         !$omp parallel do private(i, j) reduction(+:num)
         do q = 1, nc
            i = contact(1, q)
            j = contact(2, q)
            if (grid%preconditioned) then
               t(i, j) = stencil_at(i, j) - zbar + beta*t(i, j)
            else
               t(i, j) = real(gm(i, j), dp) + beta*t(i, j)
            end if
            num = num + real(gm(i, j), dp)*t(i, j)
         end do
         ! r = c (I * t): the displacements of the search direction, always in float32
         ! when float32 is on: its round-off (1e-7 of r) scales with the step, and the
         ! steps shrink with the residual, so it never limits the accuracy; the forces'
         ! own displacements (fresh) switch to double below `single_until`.
         if (allocated(r32)) then
            call convolution_apply_single(grid%conv, t, factor=c, result32=r32)
            fresh_double = .false.
         else
            call convolve(t, r, .false.)
         end if
         rt = 0
         rsum = 0
         tsum = 0
         !$omp parallel do private(i, j) reduction(+:rt, rsum, tsum)
         do q = 1, nc
            i = contact(1, q)
            j = contact(2, q)
            rt = rt + (r_at(i, j) + s*t(i, j))*t(i, j)
            rsum = rsum + r_at(i, j) + s*t(i, j)
            tsum = tsum + t(i, j)
         end do
         rbar = rsum/nc
         den = rt - rbar*tsum
         if (.not. abs(den) > 0) then
            ! Nothing left to move: the forces are the solution to round-off; accepted
            ! at the top of the loop, on fresh displacements.
            stalled = .true.
            cycle
         end if
         tau = num/den
         ! The step. Every pixel: the displacements follow linearly (w - tau r), and an
         ! overlapping pixel enters. Then the contacts: their forces step and are clipped
         ! at zero. Where the projection changed a force, the displacements need a
         ! correction: the first `limit` changes are kept (in any order; sorted below).
         nchanged = 0
         ! Each sum starts from zero in its own parallel region: how the threads' shares
         ! are added is then the same in every run (on two threads).
         psum_in = 0
         entering%n = 0
         !$omp parallel private(thread, i, j, gij, pn) reduction(+:psum_in)
         thread = 0
         !$ thread = omp_get_thread_num()
         !$omp do schedule(static)
         do j = 1, np
            do i = 1, np
               if (touching(i, j) == 0) then
                  gij = grid%g0(i, j) + alpha*w(i, j) - gbar
                  if (gij < 0) then
                     pn = -tau*entry*gij
                     p(i, j) = pn
                     psum_in = psum_in + pn
                     touching(i, j) = 1
                     ! Its gap now is its previous gap in the next iteration.
                     gm(i, j) = real(gij, sp)
                     call push_pixel(entering(thread), i, j)
                     call record_change(i, j, pn)
                  end if
               end if
               w(i, j) = alpha*w(i, j) - tau*r_at(i, j)
            end do
         end do
         !$omp end do
         !$omp end parallel
         psum = 0
         !$omp parallel do private(i, j, lin, pn) reduction(+:psum)
         do q = 1, nc
            i = contact(1, q)
            j = contact(2, q)
            lin = alpha*p(i, j) - tau*t(i, j)
            pn = max(lin, 0.0_dp)
            p(i, j) = pn
            psum = psum + pn
            if (.not. pn > 0) then
               ! Leaves the contacts: no force, no direction, no contact gap.
               touching(i, j) = 0
               t(i, j) = 0
               gm(i, j) = 0
            end if
            if (pn /= lin) call record_change(i, j, pn - lin)
         end do
         restart = how%restart_on_entry .and. sum(entering%n) > 0
         call list_contacts_after_step()
         kept_old = .false.
         fresh_double = .false.
         psum = psum + psum_in
         if (.not. psum > 0) then
            call set_error(status, STATUS_NUMERICAL, "cg: all forces vanished")
            return
         end if
         if (nchanged > 0 .and. nchanged <= capacity) call sort_changes(nchanged)
         if (nchanged > limit .and. nchanged <= split_limit) then
            ! The kernel split, with the widest window the budget allows, while its error
            ! bound (each change's far error, summed since the last fresh convolution)
            ! stays a fraction of the residual (nm).
            if (grid%split%np /= np) call split_setup(grid%split, np, how%split_cell, how%split_radius)
            reach = min(how%split_radius, int((sqrt(how%split_budget*real(np, dp)**2/nchanged) - 1)/2))
            reach = max(reach, how%split_cell)
            bound = split_error + c*grid%split%far_error(reach)*sum(abs(delta(1:nchanged)))
            if (bound <= how%split_tolerance*residual*grid%scale) then
               split_error = bound
               call split_apply(grid%split, w, c, changed, delta, nchanged, reach)
               rep%split_corrections = rep%split_corrections + 1
               fresh_double = .false.
            else
               fresh = .true.
            end if
         else if (nchanged > limit) then
            fresh = .true.
         else if (nchanged > 0) then
            call add_direct(nchanged)
         end if
         alpha = total_load/psum
      end do
      ! The forces and displacements as they stand (the load balance applied).
      !$omp parallel do private(i, j)
      do q = 1, size(contact, 2)
         i = contact(1, q)
         j = contact(2, q)
         p(i, j) = alpha*p(i, j)
      end do
      rep%iterations = rep%iterations + it
      rep%residual = residual
      rep%contact_gap = contact_gap
      rep%penetration = penetration
      rep%load_error = abs(sum(p) - total_load)/total_load
      if (present(final_gap)) then
         ! Formed in t's storage and handed over: no further NP x NP array at the peak.
         if (allocated(r)) deallocate(r)
         if (allocated(r32)) deallocate(r32)
         !$omp parallel do private(i)
         do j = 1, np
            do i = 1, np
               if (touching(i, j) /= 0) then
                  t(i, j) = 0
               else
                  t(i, j) = grid%g0(i, j) + alpha*w(i, j) - gbar
               end if
            end do
         end do
         call move_alloc(t, final_gap)
      end if
   contains
      !> The deepest overlap (nm) off the contacts, max(-gap, 0), over every pixel.
      real(dp) function deepest_overlap() result(depth)
         integer :: ii, jj
         depth = 0
         !$omp parallel do private(ii) reduction(max:depth)
         do jj = 1, np
            do ii = 1, np
               if (touching(ii, jj) == 0) depth = max(depth, -(grid%g0(ii, jj) + alpha*w(ii, jj) - gbar))
            end do
         end do
      end function deepest_overlap

      !> `contact` from `touching`: every contact pixel, column by column.
      subroutine list_contacts()
         integer :: ii, jj, n
         allocate(contact(2, count(touching /= 0)))
         n = 0
         do jj = 1, np
            do ii = 1, np
               if (touching(ii, jj) /= 0) then
                  n = n + 1
                  contact(1, n) = ii
                  contact(2, n) = jj
               end if
            end do
         end do
      end subroutine list_contacts

      !> `contact` after a step: the pixels of the list that kept a force merged with those
      !> that entered (each thread's in column order, the threads' columns in order), so
      !> the list stays in column order and every sum over it in one order.
      subroutine list_contacts_after_step()
         integer, allocatable :: new(:, :), came(:, :)
         integer :: n, k, a, b, kept, th
         kept = 0
         do k = 1, size(contact, 2)
            if (touching(contact(1, k), contact(2, k)) /= 0) kept = kept + 1
         end do
         allocate(came(2, sum(entering%n)), new(2, kept + sum(entering%n)))
         n = 0
         do th = 0, threads - 1
            if (entering(th)%n == 0) cycle
            came(:, n + 1:n + entering(th)%n) = entering(th)%ij(:, 1:entering(th)%n)
            n = n + entering(th)%n
         end do
         ! Merge by (column, row).
         a = 1
         b = 1
         n = 0
         do
            do while (a <= size(contact, 2))
               if (touching(contact(1, a), contact(2, a)) /= 0) exit
               a = a + 1
            end do
            if (a > size(contact, 2) .and. b > size(came, 2)) exit
            n = n + 1
            if (b > size(came, 2)) then
               new(:, n) = contact(:, a)
               a = a + 1
            else if (a > size(contact, 2)) then
               new(:, n) = came(:, b)
               b = b + 1
            else if (contact(2, a) < came(2, b) .or. (contact(2, a) == came(2, b) .and. contact(1, a) < came(1, b))) then
               new(:, n) = contact(:, a)
               a = a + 1
            else
               new(:, n) = came(:, b)
               b = b + 1
            end if
         end do
         call move_alloc(new, contact)
      end subroutine list_contacts_after_step

      !> Count a change of the force at pixel (i, j) by the projection, d (nN), and keep it
      !> among the first `limit` for a direct correction (called by the step's threads).
      subroutine record_change(i, j, d)
         integer, intent(in) :: i, j
         real(dp), intent(in) :: d
         integer :: slot
         !$omp atomic capture
         nchanged = nchanged + 1
         slot = nchanged
         !$omp end atomic
         if (slot <= capacity) then
            changed(1, slot) = i
            changed(2, slot) = j
            delta(slot) = d
         end if
      end subroutine record_change

      !> The displacement (nm) of the search direction at pixel (i, j), from r32 or r.
      pure real(dp) function r_at(i, j)
         integer, intent(in) :: i, j
         if (allocated(r32)) then
            r_at = real(r32(i, j), dp)
         else
            r_at = r(i, j)
         end if
      end function r_at

      !> The 13-point stencil of the inverse Love operator on the contacts' gaps gm at
      !> pixel (i, j): the preconditioned gap z.
      pure real(dp) function stencil_at(i, j)
         integer, intent(in) :: i, j
         associate(a => grid%taps)
            stencil_at = a(0, 0)*g_at(i, j) + a(1, 0)*(g_at(i - 1, j) + g_at(i + 1, j)) + &
               a(0, 1)*(g_at(i, j - 1) + g_at(i, j + 1)) + &
               a(1, 1)*(g_at(i - 1, j - 1) + g_at(i + 1, j - 1) + g_at(i - 1, j + 1) + g_at(i + 1, j + 1)) + &
               a(2, 0)*(g_at(i - 2, j) + g_at(i + 2, j)) + a(0, 2)*(g_at(i, j - 2) + g_at(i, j + 2))
         end associate
      end function stencil_at

      !> The contacts' gap gm at (i, j) in double.
      pure real(dp) function g_at(i, j)
         integer, intent(in) :: i, j
         g_at = real(gm(i, j), dp)
      end function g_at

      !> z = the stencil applied to the contacts' gaps gm (zero off the contacts), on the
      !> contacts; zbar its mean there (the direction is z - zbar); big_g = g . (z - zbar),
      !> the preconditioned norm for beta, and cross = g_old . (z - zbar) for Polak-Ribiere
      !> and Powell's restart test. z is not kept: the direction forms it again.
      subroutine precondition(big_g, zbar, cross)
         real(dp), intent(out) :: big_g, zbar, cross
         real(dp) :: zsum, gz, gsum, zo, osum, zij
         integer :: k, ii, jj
         zsum = 0
         gz = 0
         gsum = 0
         zo = 0
         osum = 0
         !$omp parallel do private(ii, jj, zij) reduction(+:zsum, gz, gsum, zo, osum)
         do k = 1, nc
            ii = contact(1, k)
            jj = contact(2, k)
            zij = stencil_at(ii, jj)
            zsum = zsum + zij
            gz = gz + real(gm(ii, jj), dp)*zij
            gsum = gsum + real(gm(ii, jj), dp)
            if (keep_old) then
               zo = zo + real(g_old(k), dp)*zij
               osum = osum + real(g_old(k), dp)
            end if
         end do
         zbar = zsum/nc
         big_g = gz - zbar*gsum
         cross = zo - zbar*osum
      end subroutine precondition

      !> w = c (I * f) with fresh transforms (float32 while `single`).
      subroutine displacements(f, out)
         real(dp), intent(in) :: f(:, :)
         real(dp), intent(out) :: out(:, :)
         call convolve(f, out, single)
         rep%convolutions = rep%convolutions + 1
         fresh_double = .not. single
      end subroutine displacements

      !> out = c (I * f), in float32 when `in_single`.
      subroutine convolve(f, out, in_single)
         real(dp), intent(in) :: f(:, :)
         real(dp), intent(out) :: out(:, :)
         logical, intent(in) :: in_single
         if (in_single) then
            call convolution_apply_single(grid%conv, f, out, c)
         else
            call convolution_apply(grid%conv, f, out, c)
         end if
         fresh_double = .false.
      end subroutine convolve

      !> Sort the first n changes by column, then row: the threads recorded them in any
      !> order, and the sums over them, and so the answer, must not depend on it. A
      !> counting sort by column, then each column's few changes by row.
      subroutine sort_changes(n)
         integer, intent(in) :: n
         integer, allocatable :: start(:), by_column(:, :)
         real(dp), allocatable :: by_delta(:)
         integer :: q, jj, slot, key(2)
         real(dp) :: d
         allocate(start(np + 1), by_column(2, n), by_delta(n))
         start = 0
         do q = 1, n
            start(changed(2, q) + 1) = start(changed(2, q) + 1) + 1
         end do
         start(1) = 1
         do jj = 2, np + 1
            start(jj) = start(jj) + start(jj - 1)
         end do
         do q = 1, n
            slot = start(changed(2, q))
            start(changed(2, q)) = slot + 1
            by_column(:, slot) = changed(:, q)
            by_delta(slot) = delta(q)
         end do
         ! Rows within a column (stable insertion; a column holds few changes).
         do q = 2, n
            key = by_column(:, q)
            d = by_delta(q)
            jj = q - 1
            do while (jj >= 1)
               if (by_column(2, jj) /= key(2) .or. by_column(1, jj) <= key(1)) exit
               by_column(:, jj + 1) = by_column(:, jj)
               by_delta(jj + 1) = by_delta(jj)
               jj = jj - 1
            end do
            by_column(:, jj + 1) = key
            by_delta(jj + 1) = d
         end do
         changed(:, 1:n) = by_column
         delta(1:n) = by_delta
      end subroutine sort_changes

      !> w += c * I * (the changed forces' corrections), summed directly from the table
      !> (the changes sorted).
      subroutine add_direct(n)
         integer, intent(in) :: n
         integer :: jj, ii, q, iq, jq
         !$omp parallel do private(ii, q, iq, jq)
         do jj = 1, np
            do q = 1, n
               iq = changed(1, q)
               jq = changed(2, q)
               do ii = 1, np
                  w(ii, jj) = w(ii, jj) + c*delta(q)*real(grid%table(abs(ii - iq), abs(jj - jq)), dp)
               end do
            end do
         end do
         fresh_double = .false.
      end subroutine add_direct
   end subroutine constrained_cg

   !> Append pixel (i, j) to `list`, growing it by doubling.
   pure subroutine push_pixel(list, i, j)
      type(pixel_list), intent(inout) :: list
      integer, intent(in) :: i, j
      integer, allocatable :: grown(:, :)
      if (.not. allocated(list%ij)) allocate(list%ij(2, 1024))
      if (list%n == size(list%ij, 2)) then
         allocate(grown(2, 2*size(list%ij, 2)))
         grown(:, 1:list%n) = list%ij(:, 1:list%n)
         call move_alloc(grown, list%ij)
      end if
      list%n = list%n + 1
      list%ij(1, list%n) = i
      list%ij(2, list%n) = j
   end subroutine push_pixel
end module femcod_cg
