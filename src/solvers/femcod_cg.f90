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
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_USAGE, STATUS_INTERRUPTED
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gap_map
   use femcod_split_correction, only: split_hand_over
   use femcod_elastic_operator, only: elastic_operator, grid_operator, grid_operator_setup, grid_operator_free, &
      spread_load, cg_constraint
   use femcod_constrained_cg, only: constrained_cg, cg_residuals
   use femcod_gap_cg, only: gap_session, gap_session_start, gap_target, gap_solver_storage_bytes
   use femcod_interface_law, only: interface_law, make_interface_law, MAX_PLASTIC_ROUNDS
   use femcod_contact_result, only: contact_result, load_state, append_step, STOP_LOADS, STOP_INTERRUPTED, gather_contacts, &
      cg_diagnostics, cg_state_diagnostics
   use femcod_solver_options, only: refuse_beyond_memory, contact_options, cg_settings, by_gap_variables, &
      requested_states, run_shear_model, &
      BOUNDARY_PERIODIC
   use femcod_observer, only: solver_observer
   use femcod_shear_model, only: friction_force
   use femcod_strings, only: count_text, int_str, sig_str, format_real
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: solve_cg, coarse_start_forces, approach_error_bound, cg_storage_bytes, distributed_storage_bytes, &
      materials_of
   public :: cg_residuals, cg_session, cg_answer, session_start, solve_target, ascending_order, &
      refuse_beyond_full_contact, unconverged_message

   !> The whole grid in one process (model/femcod_elastic_operator's grid_operator) whose
   !> solves start from nested coarser grids (nested_start, with how%nested), each made
   !> from the deck's materials kept here (no heights).
   type, extends(grid_operator) :: nested_grid_operator
      type(contact_problem) :: materials
   contains
      procedure :: start_forces => nested_grid_start
   end type nested_grid_operator

   !> What the solver carries from one target (load or approach) to the next, on this
   !> process's columns of the operator's grid: the forces (nN; the next target's warm
   !> start), the approach (nm) they give, the interface law (with --plastic its pixel
   !> force cap fmax = H d^2, nN), and with the cap the deck's gaps (nm) and the capped
   !> (plastic) pixels. Under displacement control with an adhesive law or the cap
   !> (`by_gaps`), the targets are solved in the gap variables (femcod_gap_cg), along the
   !> path in the order given, and the session carries that path too.
   type :: cg_session
      real(dp), allocatable :: p(:, :)
      real(dp) :: approach = 0
      logical :: plastic = .false.
      real(dp), allocatable :: g0(:, :)
      logical, allocatable :: capped(:, :)
      logical :: by_gaps = .false.
      type(interface_law) :: law
      type(gap_session) :: path
   end type cg_session

   !> One target's answer: the load (nN) and approach (nm), the residuals reached (over
   !> every solve the target took), the plastic rounds, and on this process's columns the
   !> gap map (nm; 0 on the elastic contacts, minus the plastic displacement on the capped
   !> pixels) and the plastic displacement map (nm, with --plastic).
   !> In the gap variables besides: the contacts are the pixels at gap 0 (with adhesion
   !> they may pull), and over the whole grid the pixels off contact within the law's
   !> range, their load (nN, negative: tension) and the mean gap (nm).
   type :: cg_answer
      real(dp) :: load = 0, approach = 0
      type(cg_residuals) :: rep
      integer :: plastic_rounds = 0
      real(dp), allocatable :: gap(:, :), plastic(:, :)
      logical :: by_gaps = .false.
      integer :: attractive = 0
      real(dp) :: attractive_load = 0, mean_gap = 0
   end type cg_answer

contains


   !> The cg solver's storage at its largest (bytes), from the arrays it holds per pixel
   !> of the NP x NP grid through the iteration: the forces, the initial gaps and the
   !> force displacements (8 bytes each); the kernel's spectrum, complex on (M/2 + 1) x NP
   !> with M = 2 NP free or NP periodic (16 or 8 bytes a pixel), and its real
   !> coefficients for one quarter of the frequencies (8 or 2); the direct corrections'
   !> float32 Love table, the stencil's padded float32 gaps and the direction's float32
   !> displacements (4 each); the contact marks (1); the contact list with the search
   !> direction on it, the kernel split's changes and mesh (4 at most up to a quarter of
   !> the pixels in contact); each state's gap map kept in memory (8; none when
   !> `streamed`: an observer takes them out as they are solved). With the plastic cap:
   !> the deck's gaps, the capped flags, the capped rounds' force, field and gap maps (8 +
   !> 4 + 24), and each state's plastic map (8). The nested coarse grids (a third of this)
   !> come and go before the fine grid's iteration. Against femcod run's peak resident
   !> memory (one load, the heights freed, doc/performance.md): 4096^2 free 65 against
   !> 64.7 bytes a pixel measured for the whole process, periodic 51 against 52.0.
   pure function cg_storage_bytes(np, nstates, periodic, plastic, streamed) result(bytes)
      integer, intent(in) :: np, nstates
      logical, intent(in) :: periodic, plastic, streamed
      integer(i8) :: bytes, n2, per_pixel
      n2 = int(np, i8)**2
      per_pixel = 3*8 + merge(8, 16, periodic) + merge(2, 8, periodic) + 3*4 + 1 + 4 + merge(0, 8*nstates, streamed)
      if (plastic) per_pixel = per_pixel + 8 + 4 + 24 + 8*nstates
      bytes = n2*per_pixel
   end function cg_storage_bytes

   !> femcod-mpi's distributed solver's storage on all ranks together (bytes; each rank
   !> holds its share), from what it allocates per pixel of the NP x NP grid. Throughout:
   !> the gaps (8), the column transforms' complex half spectrum (8 on the periodic cell,
   !> 16 padded free) and the kernel's real spectrum for half of one axis' frequencies (it
   !> is even) with its float32 copy (2 + 1, or 8 + 4 free). The set-up: the rows' buffer
   !> (8, or 32 free: rows of 2 NP for NP + 1 frequencies; the grid takes the reader's gaps,
   !> grid_setup_taking); on one node the rows' buffer is freed after it (the convolution
   !> reads its rows from the shared columns), on more than one node (`one_node` false) it
   !> stays.
   !> The iteration: the force displacements (8; the direction lives on the contacts),
   !> the stencil's float32 copy and the float32 residual (8), the contact flags (1), the
   !> forces (8), and per state held at once (`nstates`: femcod-mpi writes each state's
   !> columns as soon as it is solved and frees them, 1) its gap map (8; its forces are
   !> written from the solver's). With the plastic cap, as femcod_cg's: the deck's gaps,
   !> the capped flags, the capped rounds' force, field and gap maps (36) and per state
   !> held the plastic map (8). On one node the peak is the larger of the set-up and the
   !> iteration. Measured on one node (4096^2 text deck, 2 ranks, 1 state; femcod-mpi's
   !> estimate adds what each rank holds and the shared Love table): free 736 and 724 MB
   !> estimated against 792 and 781 MB peak resident memory (the set-up's: each rank's
   !> resident memory also counts the pages of the other ranks' columns it reads in the
   !> node's shared window), periodic 599 and 588 against 511 to 559 and 536 to 542 (two
   !> runs).
   pure function distributed_storage_bytes(np, nstates, periodic, plastic, one_node) result(bytes)
      integer, intent(in) :: np, nstates
      logical, intent(in) :: periodic, plastic, one_node
      integer(i8) :: bytes, per_pixel, throughout, setup, iteration
      throughout = 8 + merge(8, 16, periodic) + merge(2 + 1, 8 + 4, periodic)
      setup = merge(8, 32, periodic)
      iteration = 8 + 8 + 1 + 8 + 8*nstates
      if (plastic) iteration = iteration + 36 + 8*nstates
      if (one_node) then
         per_pixel = throughout + max(setup, iteration)
      else
         per_pixel = throughout + merge(8, 32, periodic) + iteration
      end if
      bytes = int(np, i8)**2*per_pixel
   end function distributed_storage_bytes

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
   !> Approaches with an adhesive law or the plastic cap are solved in the gap variables,
   !> along the path in the order given (by_gap_variables).
   subroutine solve_cg(problem, options, res, status, observer)
      !> Its height maps freed once the grid holds the initial gaps when
      !> options%release_heights.
      type(contact_problem), intent(inout) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      !> Told of every load solved (progress).
      class(solver_observer), intent(inout) :: observer
      type(cg_residuals), allocatable :: report(:)
      !> The solver's work at each state (res%diagnostics).
      type(cg_diagnostics) :: work
      type(nested_grid_operator) :: fine
      type(cg_session) :: session
      type(cg_answer) :: answer
      real(dp), allocatable :: targets(:)
      integer, allocatable :: order(:)
      real(dp) :: tstart, t0, t1
      integer :: k, kk, m
      logical :: by_approach, by_gaps
      call wall_clock(tstart)
      ! Displacement control (--approach): the targets are approaches, the loads the answers.
      by_approach = .false.
      if (allocated(options%approaches)) by_approach = size(options%approaches) > 0
      by_gaps = by_gap_variables(options)
      if (by_approach) then
         targets = options%approaches
      else
         targets = options%loads
      end if
      m = size(targets)
      allocate(report(m), res%states(m), work%states(m))
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
      call make_fine_grid(problem, options, by_gaps, fine, res%estimated_peak_bytes, status)
      if (status%code /= 0) return
      if (by_approach .and. .not. options%plastic) call refuse_beyond_full_contact(fine, targets, status)
      if (status%code /= 0) then
         call grid_operator_free(fine%grid_operator)
         return
      end if
      if (options%plastic) allocate(res%step_plastic(0))
      call session_start(fine, session, make_interface_law(options%adhesion, options%work, options%range, &
         problem%pixel, options%plastic, options%hardness), by_gaps)
      ! A path in the gap variables in the order given; loads and elastic approaches in
      ! ascending order, each from the last. The state reported in full: the last of the
      ! path, or the largest target.
      if (by_gaps) then
         order = [(k, k = 1, m)]
      else
         order = ascending_order(targets)
      end if
      do kk = 1, m
         k = order(kk)
         call wall_clock(t0)
         call solve_target(fine, session, targets(k), by_approach, options%cg, answer, status, observer)
         if (status%code /= 0) exit
         call wall_clock(t1)
         report(k) = answer%rep
         call record_answer(res, res%states(k), work%states(k), session, answer, options, by_approach, problem%pixel, &
            t1 - t0)
         if (kk > 1 .and. by_gaps) call mark_jump(res%states(order(kk - 1))%contacts, res%states(k))
         call observer%progress(kk, res%states(k)%contacts, res%states(k)%load, t1 - tstart)
         call observer%state_solved(k, m, res%states(k))
         if ((by_gaps .and. kk == m) .or. (.not. by_gaps .and. targets(k) == maxval(targets))) &
            call report_state(res, res%states(k), kk)
      end do
      call grid_operator_free(fine%grid_operator)
      allocate(res%diagnostics, source=work)
      res%stop_reason = STOP_LOADS
      if (status%code == STATUS_INTERRUPTED .and. kk > 1) then
         ! A stop signal between two targets: the states solved are kept (the caller
         ! writes them as a partial run), the last of them reported in full.
         res%stop_reason = STOP_INTERRUPTED
         if (.not. allocated(res%contact_i)) call report_state(res, res%states(order(kk - 1)), kk - 1)
      end if
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart
      if (status%code /= 0) return
      do k = 1, m
         if (report(k)%residual > options%cg%tol) then
            call set_error(status, STATUS_NUMERICAL, unconverged_message(by_approach, by_gaps, targets(k), &
               report(k)%residual, report(k)%iterations, options%cg%tol))
            return
         end if
      end do
   end subroutine solve_cg

   !> The state reported in full (the contact list of the result): `st`, solved as the
   !> `solved`-th target.
   subroutine report_state(res, st, solved)
      type(contact_result), intent(inout) :: res
      type(load_state), intent(in) :: st
      integer, intent(in) :: solved
      res%contact_i = st%i
      res%contact_j = st%j
      res%contact_step = spread(solved, 1, st%contacts)
      res%contact_force = st%force
      res%reported_load = st%load
   end subroutine report_state

   !> The message of a target whose residual stayed above --tol.
   function unconverged_message(by_approach, by_gaps, target, residual, iterations, tol) result(message)
      logical, intent(in) :: by_approach, by_gaps
      real(dp), intent(in) :: target, residual, tol
      integer, intent(in) :: iterations
      character(len=:), allocatable :: message
      if (by_gaps) then
         message = "adhesion: approach "//format_real(target)//" nm: residual "//sig_str(residual, 2)//" after "// &
            count_text(iterations, "iteration")//", above --tol "//sig_str(tol, 2)// &
            " (raise --max-iterations, or refine the pixel: adhesion_convexity in the summary)"
      else
         message = "cg: "//trim(merge("approach", "load    ", by_approach))//" "//format_real(target)// &
            trim(merge(" nm", " nN", by_approach))//": residual "//sig_str(residual, 2)//" after "// &
            count_text(iterations, "iteration")//", above --tol "//sig_str(tol, 2)//" (raise --max-iterations)"
      end if
   end function unconverged_message

   !> The grid operator for the run, after its memory estimate: the convolution, or the
   !> transform grid of the gap variables (`by_gaps`).
   subroutine make_fine_grid(problem, options, by_gaps, fine, estimated, status)
      !> Its height maps freed once the initial gaps are formed when
      !> options%release_heights: nothing after reads them.
      type(contact_problem), intent(inout) :: problem
      type(contact_options), intent(in) :: options
      logical, intent(in) :: by_gaps
      type(nested_grid_operator), intent(inout) :: fine
      integer(i8), intent(out) :: estimated
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: g0(:, :)
      integer :: m
      m = requested_states(options)
      if (by_gaps) then
         estimated = gap_solver_storage_bytes(problem%np, m, options%boundary == BOUNDARY_PERIODIC, options%plastic)
         call refuse_beyond_memory("cg --approach (gap variables): NP = "//int_str(problem%np), estimated, &
            options%memory_available, status)
      else
         estimated = cg_storage_bytes(problem%np, m, options%boundary == BOUNDARY_PERIODIC, options%plastic, &
            options%states_streamed)
         call refuse_beyond_memory("cg: NP = "//int_str(problem%np), estimated, options%memory_available, status)
      end if
      if (status%code /= 0) return
      g0 = initial_gap_map(problem%lower, problem%upper)
      if (options%release_heights) deallocate(problem%lower, problem%upper)
      call grid_operator_setup(fine%grid_operator, g0, problem, problem%pixel, options%cg, &
         options%boundary == BOUNDARY_PERIODIC, gap_variables=by_gaps)
      fine%materials = materials_of(problem)
   end subroutine make_fine_grid

   !> The deck's grid, pixel, MAXCONT and materials, without its label and heights (what a
   !> coarse start needs: the nested operator's and femcod-mpi's rank 0).
   pure function materials_of(problem) result(materials)
      type(contact_problem), intent(in) :: problem
      type(contact_problem) :: materials
      materials = contact_problem(label="", np=problem%np, pixel=problem%pixel, maxcont=problem%maxcont, &
         young=problem%young, poisson=problem%poisson)
   end function materials_of

   !> One target's state from its answer and the session's forces (nN), on the whole grid
   !> of pixel `pixel` (nm); `seconds` its solve's wall time.
   subroutine record_answer(res, st, work, session, answer, options, by_approach, pixel, seconds)
      type(contact_result), intent(inout) :: res
      type(load_state), intent(inout) :: st
      type(cg_state_diagnostics), intent(inout) :: work
      type(cg_session), intent(in) :: session
      type(cg_answer), intent(inout) :: answer
      type(contact_options), intent(in) :: options
      logical, intent(in) :: by_approach
      real(dp), intent(in) :: pixel, seconds
      logical, allocatable :: contact(:, :)
      associate(p => session%p)
         if (answer%by_gaps) then
            contact = answer%gap == 0
         else
            contact = p > 0
         end if
         st%load = answer%load
         st%reached = .true.
         st%approach = answer%approach
         work%iterations = answer%rep%iterations
         work%residual = answer%rep%residual
         work%penetration = answer%rep%penetration
         work%contact_gap = answer%rep%contact_gap
         work%load_error = answer%rep%load_error
         if (.not. (by_approach .or. options%plastic .or. &
            options%boundary == BOUNDARY_PERIODIC .or. options%cg%kernel_radius > 0)) work%approach_bound = &
            approach_error_bound(work%penetration, work%contact_gap, work%load_error, st%approach)
         work%coarse_iterations = answer%rep%coarse_iterations
         work%convolutions = answer%rep%convolutions
         work%split_corrections = answer%rep%split_corrections
         work%plastic_rounds = answer%plastic_rounds
         if (allocated(answer%gap)) call move_alloc(answer%gap, st%gap)
         ! The mean gap over the grid (nm): the gap variables' own where they ran.
         if (.not. answer%by_gaps .and. allocated(st%gap)) st%mean_gap = sum(st%gap)/real(size(st%gap), dp)
         if (allocated(answer%plastic)) call move_alloc(answer%plastic, st%plastic)
         st%contacts = count(contact)
         st%max_pressure = 0
         if (st%contacts > 0) st%max_pressure = maxval(p, mask=contact)/pixel**2
         st%n_above_hardness = count(p/pixel**2 > options%hardness)
         if (options%plastic) then
            st%n_plastic = count(session%capped)
            st%plastic_volume = sum(st%plastic)*pixel**2
         end if
         st%attractive = answer%attractive
         st%attractive_load = answer%attractive_load
         if (answer%by_gaps) st%mean_gap = answer%mean_gap
         call gather_contacts(st, contact, p)
         st%friction = friction_force(run_shear_model(options), st%force, pixel)
         call append_step(res, st%contacts, st%n_above_hardness, st%load, st%approach, seconds, st%friction)
         if (options%plastic) res%step_plastic = [res%step_plastic, st%n_plastic]
      end associate
   end subroutine record_answer

   !> A contact set that appears from none, or vanishes, between two approaches of a path
   !> is a jump (into contact, or pull-off): the state left its branch.
   pure subroutine mark_jump(previous_contacts, st)
      integer, intent(in) :: previous_contacts
      type(load_state), intent(inout) :: st
      st%jump = 0
      if (previous_contacts == 0 .and. st%contacts > 0) st%jump = 1
      if (previous_contacts > 0 .and. st%contacts == 0) st%jump = -1
   end subroutine mark_jump

   !> A periodic cell is in full contact when the approach (the fall of the mean gap)
   !> reaches the mean initial gap; there any load above the full-contact load gives that
   !> approach, and beyond it none does (the elastic displacements have no mean): such an
   !> approach is refused.
   subroutine refuse_beyond_full_contact(grid, approaches, status)
      class(elastic_operator), intent(inout) :: grid
      real(dp), intent(in) :: approaches(:)
      type(status_type), intent(inout) :: status
      real(dp) :: mean_gap(1)
      if (.not. grid%periodic) return
      mean_gap(1) = sum(grid%g0)
      call grid%sum_over_grid(mean_gap)
      mean_gap = mean_gap/real(grid%np, dp)**2
      if (maxval(approaches) >= mean_gap(1)) call set_error(status, STATUS_USAGE, "--approach "// &
         format_real(maxval(approaches))//" nm reaches the periodic cell's mean gap ("//format_real(mean_gap(1))// &
         " nm): full contact, where the approach no longer determines the load; give --loads for loads beyond "// &
         "full contact")
   end subroutine refuse_beyond_full_contact

   !> The order in which targets are solved: ascending, each warm-started from the last
   !> (a stable insertion sort: equal targets in the order given).
   pure function ascending_order(targets) result(order)
      real(dp), intent(in) :: targets(:)
      integer, allocatable :: order(:)
      integer :: k, kk
      order = [(k, k = 1, size(targets))]
      do k = 2, size(targets)
         kk = k
         do while (kk > 1)
            if (targets(order(kk - 1)) <= targets(order(kk))) exit
            order([kk - 1, kk]) = order([kk, kk - 1])
            kk = kk - 1
         end do
      end do
   end function ascending_order

   !> A session on `grid` with the interface `law`: no forces yet; with the law's cap, its
   !> fmax (nN) per pixel and the deck's gaps kept (the capped rounds move the operator's).
   !> With `by_gaps` the targets are approaches solved in the gap variables (the grid made
   !> with its transform grid).
   subroutine session_start(grid, session, law, by_gaps)
      class(elastic_operator), intent(in) :: grid
      type(cg_session), intent(out) :: session
      type(interface_law), intent(in) :: law
      logical, intent(in) :: by_gaps
      session%law = law
      session%by_gaps = by_gaps
      if (session%by_gaps) call gap_session_start(grid, session%path)
      allocate(session%p(grid%np, grid%nj))
      session%p = 0
      session%approach = 0
      session%plastic = law%capped()
      if (session%plastic) then
         session%g0 = grid%g0
         allocate(session%capped(grid%np, grid%nj))
         session%capped = .false.
      end if
   end subroutine session_start

   !> One target: the load `target` (nN), or with `by_approach` the approach `target`
   !> (nm), solved from the session's forces; the answer, and the session moved on to it.
   !> The same on one core and on ranks: everything over the grid goes through `grid`.
   subroutine solve_target(grid, session, target, by_approach, how, answer, status, observer)
      class(elastic_operator), intent(inout) :: grid
      type(cg_session), intent(inout) :: session
      real(dp), intent(in) :: target
      logical, intent(in) :: by_approach
      type(cg_settings), intent(in) :: how
      type(cg_answer), intent(out) :: answer
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      if (session%by_gaps) then
         call solve_by_gaps(grid, session, target, how, answer, status, observer)
      else
         call solve_state(grid, session, cg_constraint(target, by_approach), how, answer, status, observer)
      end if
      answer%approach = session%approach
   end subroutine solve_target

   !> The approach `target` (nm) on the session's path in the gap variables (femcod_gap_cg):
   !> the forces and the approach into the session, the gaps (and with the cap the plastic
   !> displacement and the capped set) into `answer`, with the load and the attractive
   !> zone's sums over the whole grid.
   subroutine solve_by_gaps(grid, session, target, how, answer, status, observer)
      class(elastic_operator), intent(inout) :: grid
      type(cg_session), intent(inout) :: session
      real(dp), intent(in) :: target
      type(cg_settings), intent(in) :: how
      type(cg_answer), intent(inout) :: answer
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp) :: total(4)
      answer%by_gaps = .true.
      call gap_target(grid, session%law, session%path, grid%g0, target, how%tol, how%max_iterations, &
         answer%rep%iterations, answer%rep%residual, status, observer)
      if (status%code /= 0) return
      associate(g => session%path%g, force => session%path%force)
         session%p = force
         session%approach = target
         answer%gap = g
         if (session%plastic) then
            answer%plastic = session%path%plastic
            session%capped = session%path%cap
         end if
         ! Without adhesion only the contact pixels (g = 0) carry force; what the iteration
         ! leaves elsewhere is its residual, so the load is the pressure map's sum (a state
         ! off contact is load 0, not the residual's 1e-12 nN).
         if (session%law%adhesive()) then
            total(1) = sum(force)
         else
            total(1) = sum(force, mask=g == 0)
         end if
         total(2:) = [real(count(g > 0 .and. g < session%law%range), dp), sum(force, mask=g > 0), sum(g)]
         call grid%sum_over_grid(total)
         answer%load = total(1)
         answer%attractive = nint(total(2))
         answer%attractive_load = total(3)
         answer%mean_gap = total(4)/real(grid%np, dp)**2
      end associate
   end subroutine solve_by_gaps

   !> The state under `target`, a load (nN) or an approach (nm): the forces (warm start:
   !> the session's, scaled by the solver's load balance to the load, or to the contacts'
   !> mean gap at the approach) and the approach into the session; the load and the maps
   !> into `answer`. At no load, or at or below first touch (approach <= 0), the surfaces
   !> do not touch: load 0, no contact. With the cap at a load: capped_solve (an approach
   !> with the cap is solved in the gap variables).
   subroutine solve_state(grid, session, target, how, answer, status, observer)
      class(elastic_operator), intent(inout) :: grid
      type(cg_session), intent(inout) :: session
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      type(cg_answer), intent(inout) :: answer
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp) :: total(1)
      answer%load = target%value
      if (target%value <= 0) then
         session%p = 0
         total(1) = minval(grid%g0)
         call grid%min_over_grid(total)
         session%approach = -total(1)
         if (session%plastic) session%capped = .false.
         if (target%by_approach) then
            session%approach = target%value
            answer%load = 0
         end if
      else if (session%plastic) then
         call capped_solve(grid, session, target%value, how, answer, status, observer)
      else
         total(1) = sum(session%p)
         call grid%sum_over_grid(total)
         if (.not. total(1) > 0) then
            call start_forces(grid, target, how, .true., session%p, answer%rep, status, observer)
            if (status%code /= 0) return
         end if
         call constrained_cg(grid, target, how%tol, how%max_iterations, how, session%p, session%approach, answer%rep, &
            status, observer, answer%gap)
         if (target%by_approach) then
            total(1) = sum(session%p)
            call grid%sum_over_grid(total)
            answer%load = total(1)
         end if
      end if
   end subroutine solve_state

   !> The forces (nN) a solve under `target` starts from: with `coarse`, as the operator
   !> starts (nested coarser grids on one process, a coarse solve on rank 0 in femcod-mpi;
   !> spread_load by default), else spread_load (a load spread near the first touch, or
   !> the pixels that overlap at an approach).
   subroutine start_forces(grid, target, how, coarse, p, rep, status, observer)
      class(elastic_operator), intent(inout) :: grid
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      logical, intent(in) :: coarse
      real(dp), intent(out) :: p(:, :)
      type(cg_residuals), intent(inout) :: rep
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      if (coarse) then
         call grid%start_forces(target, how, p, rep%coarse_iterations, status, observer)
      else
         call spread_load(grid, target, p)
      end if
   end subroutine start_forces

   !> The nested grid operator's start: nested_start with how%nested, else spread_load.
   subroutine nested_grid_start(op, target, how, p, coarse_iterations, status, observer)
      class(nested_grid_operator), intent(inout) :: op
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      real(dp), intent(out) :: p(:, :)
      integer, intent(inout) :: coarse_iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(cg_residuals) :: rep
      if (.not. how%nested) then
         call spread_load(op, target, p)
         return
      end if
      rep%coarse_iterations = coarse_iterations
      call nested_start(op, op%materials, target, how, p, rep, status, observer)
      coarse_iterations = rep%coarse_iterations
   end subroutine nested_grid_start

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
   !> Into the session: the forces (fmax on the capped pixels), the approach, the plastic
   !> set; into `answer`: the gap map (0 on the elastic contacts, minus the plastic
   !> displacement on the capped ones) and the plastic displacement map.
   subroutine capped_solve(grid, session, load, how, answer, status, observer)
      class(elastic_operator), intent(inout) :: grid
      type(cg_session), intent(inout) :: session
      real(dp), intent(in) :: load
      type(cg_settings), intent(in) :: how
      type(cg_answer), intent(inout) :: answer
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      !> The gap that takes a capped pixel out of the elastic problem (it never touches).
      real(dp), parameter :: EXCLUDED = 1.0e30_dp
      real(dp), allocatable :: force(:, :), w(:, :), gap(:, :)
      logical, allocatable :: grow(:, :), release(:, :)
      real(dp) :: left, total(2)
      integer :: round, ncap
      associate(p => session%p, capped => session%capped, g0 => session%g0, fmax => session%law%fmax)
      allocate(force(size(p, 1), size(p, 2)), w(size(p, 1), size(p, 2)), grow(size(p, 1), size(p, 2)), &
         release(size(p, 1), size(p, 2)))
      do round = 1, MAX_PLASTIC_ROUNDS
         total = [real(count(capped), dp), sum(p)]
         call grid%sum_over_grid(total)
         ncap = nint(total(1))
         if (ncap > 0) then
            force = merge(fmax, 0.0_dp, capped)
            call grid%displace(force, w)
            grid%g0 = merge(EXCLUDED, g0 + w, capped)
            where (capped) p = 0
            total(2) = sum(p)
            call grid%sum_over_grid(total(2:2))
         else
            grid%g0 = g0
         end if
         left = load - ncap*fmax
         if (.not. total(2) > 0) then
            call start_forces(grid, cg_constraint(left, .false.), how, ncap == 0, p, answer%rep, status, observer)
            if (status%code /= 0) exit
         end if
         call constrained_cg(grid, cg_constraint(left, .false.), how%tol, how%max_iterations, how, p, &
            session%approach, answer%rep, status, observer, answer%gap)
         if (status%code /= 0) exit
         ! The gaps of all forces together, from one fresh double-precision convolution.
         force = merge(fmax, p, capped)
         call grid%displace(force, w)
         gap = g0 - session%approach + w + grid%s*force
         call session%law%plastic_round(p, gap, how%tol*max(grid%scale, abs(session%approach)), capped, grow, release)
         if (.not. grid%any_over_grid(any(grow) .or. any(release))) exit
         ! A released pixel starts from the force it had.
         where (release) p = fmax
      end do
      grid%g0 = g0
      answer%plastic_rounds = min(round, MAX_PLASTIC_ROUNDS)
      if (status%code /= 0) return
      if (round > MAX_PLASTIC_ROUNDS) then
         call set_error(status, STATUS_NUMERICAL, "cg --plastic: the plastic set did not settle in "// &
            int_str(MAX_PLASTIC_ROUNDS)//" rounds at load "//format_real(load)//" nN")
         return
      end if
      p = merge(fmax, p, capped)
      if (allocated(answer%plastic)) deallocate(answer%plastic)
      allocate(answer%plastic(size(p, 1), size(p, 2)))
      answer%plastic = 0
      if (grid%any_over_grid(any(capped))) then
         answer%gap = merge(0.0_dp, gap, p > 0 .and. .not. capped)
         where (capped) answer%plastic = max(-gap, 0.0_dp)
      end if
      end associate
   end subroutine capped_solve

   !> The first target's start from nested grids: halve while the side stays even and at
   !> least 2 * coarsest; solve the coarsest from the first guess, then each finer grid
   !> from the coarser solution, to coarse_tol; return the forces on the finest grid.
   !> An approach is measured on each grid from its own first touch (coarse_target).
   recursive subroutine nested_start(grid, problem, target, how, p, rep, status, observer)
      class(grid_operator), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      real(dp), intent(out) :: p(:, :)
      type(cg_residuals), intent(inout) :: rep
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(grid_operator) :: coarse
      type(cg_residuals) :: coarse_rep
      real(dp), allocatable :: pc(:, :)
      real(dp) :: approach
      integer :: n, i, j
      n = grid%np
      if (mod(n, 2) /= 0 .or. n < 2*how%coarsest) then
         call spread_load(grid, coarse_target(target, grid%g0), p)
         return
      end if
      n = n/2
      call grid_operator_setup(coarse, (grid%g0(1::2, 1::2) + grid%g0(2::2, 1::2) + grid%g0(1::2, 2::2) + &
         grid%g0(2::2, 2::2))/4, problem, 2*grid%pixel, how, grid%periodic)
      allocate(pc(n, n))
      call nested_start(coarse, problem, target, how, pc, rep, status, observer)
      if (status%code == 0) call constrained_cg(coarse, coarse_target(target, coarse%g0), how%coarse_tol, 10000, how, &
         pc, approach, coarse_rep, status, observer)
      call split_hand_over(coarse%split, grid%split)
      call grid_operator_free(coarse)
      if (status%code /= 0) return
      rep%coarse_iterations = rep%coarse_iterations + coarse_rep%iterations + coarse_rep%coarse_iterations
      do j = 1, n
         do i = 1, n
            p(2*i - 1:2*i, 2*j - 1:2*j) = pc(i, j)/4
         end do
      end do
   end subroutine nested_start

   !> The forces (nN) at total load P (nN) on a grid of gaps g0 (nm) and pixel `pixel`
   !> (nm), free surface or one periodic cell, solved from its own nested start to
   !> how%coarse_tol: the start that the distributed solver (femcod-mpi) hands down to its
   !> finer grid, as nested_start does here. `iterations`: on this grid and all coarser
   !> ones.
   subroutine coarse_start_forces(g0, problem, pixel, target, how, periodic, p, iterations, status, observer)
      real(dp), intent(in) :: g0(:, :)
      type(contact_problem), intent(in) :: problem
      type(cg_constraint), intent(in) :: target
      real(dp), intent(in) :: pixel
      type(cg_settings), intent(in) :: how
      logical, intent(in) :: periodic
      real(dp), intent(out) :: p(:, :)
      integer, intent(out) :: iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(grid_operator) :: grid
      type(cg_residuals) :: rep
      real(dp) :: approach
      call grid_operator_setup(grid, g0, problem, pixel, how, periodic)
      if (how%nested) then
         call nested_start(grid, problem, target, how, p, rep, status, observer)
      else
         call spread_load(grid, coarse_target(target, g0), p)
      end if
      if (status%code == 0) call constrained_cg(grid, coarse_target(target, g0), how%coarse_tol, 10000, how, p, &
         approach, rep, status, observer)
      call grid_operator_free(grid)
      iterations = rep%iterations + rep%coarse_iterations
   end subroutine coarse_start_forces

   !> `target` on a coarser grid of gaps g0 (nm, this process's whole grid): a load as it
   !> is; an approach A (from the finest grid's first touch) moved to the same depth below
   !> this grid's own first touch, A + min g0 (averaging the heights raises the lowest
   !> gap, and the coarse solution is only a start).
   pure function coarse_target(target, g0) result(coarse)
      type(cg_constraint), intent(in) :: target
      real(dp), intent(in) :: g0(:, :)
      type(cg_constraint) :: coarse
      coarse = target
      if (target%by_approach) coarse%value = target%value + minval(g0)
   end function coarse_target
end module femcod_cg
