!> One interface to the three solvers: a problem and its options in, one result out,
!> with an optional observer for progress and checkpoints. `femcod run`, the studies,
!> the stability cases and the benchmarks all solve through `solve_contact`. What each
!> solver left out of the model, and what it checked, comes back as text lines for
!> the summary and the run record (no I/O here).
module femcod_solver
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_strings, only: count_text, string_type, int_str, sig_str, format_real
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gap_map
   use femcod_love, only: surface_compliance, love_influence
   use femcod_spring, only: spring_stiffness
   use femcod_contact_result, only: contact_result, load_state, cg_diagnostics, cg_state_diagnostics, &
      event_path_diagnostics, legacy_diagnostics, stop_reason_text
   use femcod_solver_options, only: contact_options, validate_options, by_gap_variables, run_shear_model, &
      refuse_beyond_memory, &
      SOLVER_INCREMENTAL, SOLVER_LEGACY, SOLVER_CG, BOUNDARY_PERIODIC, LAW_HARD_WALL, law_name
   use femcod_observer, only: solver_observer
   use femcod_legacy, only: solve_legacy
   use femcod_incremental, only: solve_incremental
   use femcod_incremental_state, only: incremental_state
   use femcod_cg, only: solve_cg
   use femcod_gap_cg, only: pixel_stiffness_ratio
   use femcod_shear_model, only: shear_model
   use femcod_cerruti, only: second_dundurs_constant
   use femcod_clock, only: wall_clock
   use femcod_tangential, only: tangential_request, tangential_answer, solve_tangential_on, keep_tangential_answer, &
      tangential_storage_bytes, tangential_request_of
   use femcod_shear_operator, only: grid_shear_operator, grid_shear_setup, grid_shear_free
   implicit none
   private
   public :: solve_contact, model_notes, report_lines, report_line, run_warnings

   !> A line of the summary: a label ("checked", "cg", ...) and its text.
   type :: report_line
      character(len=:), allocatable :: label, text
   end type report_line

contains

   !> Solve `problem` with the solver options%solver names. `resume` (incremental solver
   !> only) continues a run from a stored state.
   subroutine solve_contact(problem, options, res, status, observer, resume)
      !> Without its height maps on return when options%release_heights (cg only).
      type(contact_problem), intent(inout) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout), optional :: observer
      type(incremental_state), intent(inout), optional :: resume
      type(solver_observer) :: nobody
      if (status%code /= 0) return
      call validate_options(options, status)
      if (status%code /= 0) return
      ! The fixed-load solver cannot carry more than every pixel at H d^2; the event path
      ! stops where no pixel is left to touch, and says which loads it did not reach.
      if (options%plastic .and. options%solver == SOLVER_CG .and. allocated(options%loads)) then
         if (size(options%loads) > 0) then
            if (maxval(options%loads) >= real(problem%np, dp)**2*options%hardness*problem%pixel**2) then
               call set_error(status, STATUS_USAGE, "--plastic: load "//format_real(maxval(options%loads))// &
                  " nN is at or above the fully plastic capacity NP^2 H d^2 = "// &
                  format_real(real(problem%np, dp)**2*options%hardness*problem%pixel**2)//" nN")
               return
            end if
         end if
      end if
      call refuse_periodic_full_contact(problem, options, status)
      call refuse_beyond_float32(problem, options, status)
      if (status%code /= 0) return
      if (present(resume) .and. options%solver /= SOLVER_INCREMENTAL) then
         call set_error(status, STATUS_USAGE, "only the incremental solver continues from a stored state")
         return
      end if
      select case (options%solver)
      case (SOLVER_INCREMENTAL)
         if (present(observer)) then
            call solve_incremental(problem, options, res, status, observer, resume)
         else
            call solve_incremental(problem, options, res, status, nobody, resume)
         end if
      case (SOLVER_LEGACY)
         if (present(observer)) then
            call solve_legacy(problem, options, res, status, observer)
         else
            call solve_legacy(problem, options, res, status, nobody)
         end if
      case (SOLVER_CG)
         if (present(observer)) then
            call solve_cg(problem, options, res, status, observer)
         else
            call solve_cg(problem, options, res, status, nobody)
         end if
      case default
         call set_error(status, STATUS_USAGE, "unknown solver "//int_str(options%solver)// &
            " (available: incremental, legacy, cg)")
      end select
      if (options%tangential .and. allocated(res%states) .and. status%code == 0) then
         if (present(observer)) then
            call tangential_states(problem, options, res, status, observer)
         else
            call tangential_states(problem, options, res, status, nobody)
         end if
      end if
   end subroutine solve_contact

   !> The cg iteration keeps its gradient in float32 (and transforms in it while far from
   !> the answer): a load whose displacements, between P c I(0,0) on one pixel and that
   !> over NP^2 spread on all, leave float32's range (1e-38 to 3e38) cannot be solved by
   !> it (a load of 1e-300 or 1e300 nN on a flat: 2000 iterations, residual 0.25).
   !> Refused (exit 2) before any work; the event solvers, in double throughout, take it.
   subroutine refuse_beyond_float32(problem, options, status)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(status_type), intent(inout) :: status
      real(dp), parameter :: SMALLEST = 1.0e-30_dp, LARGEST = 1.0e30_dp
      real(dp) :: unit, low, high
      if (status%code /= 0 .or. options%solver /= SOLVER_CG) return
      if (.not. allocated(options%loads)) return
      if (size(options%loads) == 0) return
      unit = (surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), problem%pixel))*love_influence(0, 0)
      low = minval(abs(options%loads), mask=options%loads /= 0)*unit/real(problem%np, dp)**2
      high = maxval(abs(options%loads))*unit
      if (any(options%loads /= 0) .and. (low < SMALLEST .or. high > LARGEST)) call set_error(status, STATUS_USAGE, &
         "--solver cg at loads from "//sig_str(minval(abs(options%loads), mask=options%loads /= 0), 3)//" to "// &
         sig_str(maxval(abs(options%loads)), 3)//" nN: displacements from "//sig_str(low, 2)//" to "// &
         sig_str(high, 2)//" nm, outside the 1e-30 to 1e30 nm that its float32 gradient holds; use --solver "// &
         "incremental (double throughout), or units that bring the loads nearer 1")
   end subroutine refuse_beyond_float32

   !> The event solvers on a periodic cell: an approach at or beyond the mean initial gap
   !> puts the cell in full contact, where the approach no longer determines the load
   !> (the elastic displacements have no mean; only the interface springs' stiffness
   !> would answer, 6.5e13 nN for 0.01 nm into a flat 64^2 cell). Refused, as the cg
   !> solver refuses it on its grid (femcod_cg's refuse_beyond_full_contact).
   subroutine refuse_periodic_full_contact(problem, options, status)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(status_type), intent(inout) :: status
      real(dp) :: mean_gap
      if (options%boundary /= BOUNDARY_PERIODIC .or. options%solver == SOLVER_CG) return
      if (.not. allocated(options%approaches)) return
      if (size(options%approaches) == 0) return
      mean_gap = sum(initial_gap_map(problem%lower, problem%upper))/real(problem%np, dp)**2
      if (maxval(options%approaches) >= mean_gap) call set_error(status, STATUS_USAGE, "--approach "// &
         format_real(maxval(options%approaches))//" nm reaches the periodic cell's mean gap ("// &
         format_real(mean_gap)//" nm): full contact, where the approach no longer determines the load; give "// &
         "--loads for loads beyond full contact")
   end subroutine refuse_periodic_full_contact

   !> What a finished run must tell its user that is not an error, one line each: every
   !> requested state not reached (with the reason the run stopped), and every reached
   !> state where the tangential step asked for could not be applied (no contact carries
   !> it). The command line prints them as warnings, the C library and Python return them.
   function run_warnings(options, res) result(lines)
      type(contact_options), intent(in) :: options
      type(contact_result), intent(in) :: res
      type(string_type), allocatable :: lines(:)
      logical :: by_approach
      integer, allocatable :: missed(:), idle(:)
      character(len=:), allocatable :: what, unit
      integer :: k
      allocate(lines(0))
      if (.not. allocated(res%states)) return
      by_approach = .false.
      if (allocated(options%approaches)) by_approach = size(options%approaches) > 0
      what = trim(merge("approach", "load    ", by_approach))
      unit = trim(merge(" nm", " nN", by_approach))
      missed = pack([(k, k = 1, size(res%states))], .not. res%states%reached)
      idle = [integer ::]
      if (options%tangential) idle = pack([(k, k = 1, size(res%states))], res%states%reached .and. &
         res%states%contacts == 0)
      ! Up to three states one by one; more as one line (a run stopped early may leave
      ! hundreds).
      if (size(missed) > 3) then
         lines = [lines, string_type(count_text(size(missed), what)//" of "//int_str(size(res%states))// &
            " not reached, from "//format_real(target(missed(1)))//" to "// &
            format_real(target(missed(size(missed))))//unit//" ("//stop_reason_text(res%stop_reason)//")")]
      else
         do k = 1, size(missed)
            lines = [lines, string_type(what//" "//format_real(target(missed(k)))//unit//" not reached ("// &
               stop_reason_text(res%stop_reason)//")")]
         end do
      end if
      if (size(idle) > 3) then
         lines = [lines, string_type(count_text(size(idle), "state")//" (states "//int_str(idle(1))//" to "// &
            int_str(idle(size(idle)))//") have no contact: the tangential step was not applied there, and their "// &
            "tangential force is 0")]
      else
         do k = 1, size(idle)
            lines = [lines, string_type("state "//int_str(idle(k))//" (approach "// &
               format_real(res%states(idle(k))%approach)//" nm) has no contact: the tangential step was not "// &
               "applied, and its tangential force is 0")]
         end do
      end if
   contains
      real(dp) function target(k)
         integer, intent(in) :: k
         target = merge(res%states(k)%approach, res%states(k)%load, by_approach)
      end function target
   end function run_warnings

   !> The tangential step (solvers/femcod_tangential) at each reached state with contacts,
   !> after its memory check, on one operator for all of them: the answer into the state.
   subroutine tangential_states(problem, options, res, status, observer)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(inout) :: res
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(tangential_request) :: request
      type(tangential_answer) :: answer
      type(grid_shear_operator) :: op
      real(dp) :: t0, t1
      integer :: k
      call wall_clock(t0)
      call refuse_beyond_memory("the tangential step: NP = "//int_str(problem%np), &
         tangential_storage_bytes(problem%np), options%memory_available, status)
      if (status%code /= 0) return
      request = tangential_request_of(options)
      if (any([(res%states(k)%reached .and. res%states(k)%contacts > 0, k = 1, size(res%states))])) &
         call grid_shear_setup(op, problem, request%periodic)
      do k = 1, size(res%states)
         associate(s => res%states(k))
            ! A state without contact carries no tangential force: no step (run_warnings).
            if (.not. s%reached .or. .not. allocated(s%force) .or. s%contacts == 0) cycle
            call solve_tangential_on(op, s%i, s%j, s%force, request, answer, status, observer)
            if (status%code /= 0) then
               status%message = "state "//int_str(k)//" (load "//sig_str(s%load, 6)//" nN): "//status%message
               call grid_shear_free(op)
               return
            end if
            call keep_tangential_answer(answer, s%state_values)
         end associate
      end do
      call grid_shear_free(op)
      ! The solve's wall time includes the tangential steps.
      call wall_clock(t1)
      res%wall_seconds = res%wall_seconds + (t1 - t0)
   end subroutine tangential_states

   !> What the solver's model leaves out for this problem, one line each (the summary's
   !> "model" lines and /run/scene_left_out): the solver's own, then the shear model's.
   function model_notes(problem, options) result(lines)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(string_type), allocatable :: lines(:)
      type(shear_model) :: shear
      character(len=:), allocatable :: cap
      lines = solver_notes(problem, options)
      if (options%tangential) lines = [lines, string_type("tangential step (Coulomb, mu = "// &
         sig_str(options%friction, 4)//"): the Cerruti kernel of the "//trim(merge("periodic cell  ", "free half-space", &
         options%boundary == BOUNDARY_PERIODIC))//", the normal pressures as the "// &
         "normal problem left them (Goodman's approximation; Dundurs' beta = "// &
         sig_str(second_dundurs_constant(problem%young(1:2), problem%poisson(1:2)), 3)//", exact only at 0: one "// &
         "material or incompressible bodies)")]
      if (.not. options%shear) return
      shear = run_shear_model(options)
      cap = "not capped (--plastic caps it at the shear yield stress)"
      if (options%plastic) cap = "capped at k = H/(3 sqrt 3) = "//sig_str(shear%tau_max, 4)//" GPa (H = 3Y, "// &
         "von Mises k = Y/sqrt 3)"
      lines = [lines, string_type("friction from the pressures (thesis 5.2.3): tau(p) = "// &
         sig_str(shear%tau0, 4)//" GPa + "//sig_str(shear%alpha, 4)//" p on each contact pixel, "//cap// &
         "; F_t = sum tau d^2, no solve: the surfaces' tangential displacements (Cerruti) are not modelled")]
   end function model_notes

   !> The solver's own notes (model_notes).
   function solver_notes(problem, options) result(lines)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(string_type), allocatable :: lines(:)
      real(dp) :: c1, c2, s, cself, ratio
      character(len=:), allocatable :: verdict
      select case (options%solver)
      case (SOLVER_LEGACY)
         lines = [string_type("nothing: the legacy solver models every node and spring of Appendix B")]
         return
      case (SOLVER_CG)
         lines = [string_type("handles and springs condensed: one composite compliance c1 + c2 with the springs' "// &
            "3/k on the diagonal, one composite gap")]
         if (options%adhesion /= LAW_HARD_WALL) then
            ratio = pixel_stiffness_ratio(problem, options%work, options%range)
            if (ratio < 1) then
               verdict = " (below 1: the discrete problem is convex at the pixel scale)"
            else
               verdict = " (above 1: single pixels may snap; a finer pixel resolves the range)"
            end if
            lines = [lines, string_type(law_name(options%adhesion)//" adhesion: W = "//sig_str(options%work, 4)// &
               " J/m^2, range "//sig_str(options%range, 4)//" nm; displacement control, each approach from the last "// &
               "(gap-variable constrained CG, Rey, Anciaux and Molinari 2017)"), &
               string_type("adhesion_convexity: one pixel's adhesive stiffness d^2 W/R^2 over its elastic "// &
               "stiffness = "//sig_str(ratio, 3)//verdict)]
         end if
         if (options%plastic .and. options%adhesion == LAW_HARD_WALL .and. by_gap_variables(options)) lines = [lines, &
            string_type("plastic cap H = "//sig_str(options%hardness, 4)//" GPa under displacement control: each "// &
            "approach from the last in the gap variables (constrained CG, Rey, Anciaux and Molinari 2017), a "// &
            "capped pixel's interpenetration kept as plastic displacement (give intermediate approaches to follow "// &
            "a path finer than the one asked)")]
         if (.not. options%plastic) lines = [lines, string_type("no plastic cap: pressures are elastic, "// &
            "n_above_hardness counts the pixels above the hardness (--plastic caps them)")]
         if (options%boundary == BOUNDARY_PERIODIC) lines = [lines, periodic_note(problem%np, SOLVER_CG)]
         if (options%cg%kernel_radius > 0) lines = [lines, string_type("Love kernel truncated beyond "// &
            sig_str(options%cg%kernel_radius, 4)//" pixels (--kernel-radius): an approximation, the convolution "// &
            "still by FFT; its error on the benchmark surface: doc/performance.md, the frontier")]
         return
      end select
      c1 = surface_compliance(problem%young(1), problem%poisson(1), problem%pixel)
      c2 = surface_compliance(problem%young(2), problem%poisson(2), problem%pixel)
      s = 3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)
      cself = (c1 + c2)*love_influence(0, 0)
      lines = [string_type("handles, substrate and surface nodes condensed: unknowns are the contact forces and "// &
         "the approach")]
      if (c2 < c1*1.0e-3_dp) then
         lines = [lines, string_type("upper body rigid (compliance "//es(c2/c1)//" of the lower's): no element of "// &
            "its own, kept exactly in c = c1 + c2")]
      else if (c1 < c2*1.0e-3_dp) then
         lines = [lines, string_type("lower body rigid (compliance "//es(c1/c2)//" of the upper's): no element of "// &
            "its own, kept exactly in c = c1 + c2")]
      else if (problem%young(1) == problem%young(2) .and. problem%poisson(1) == problem%poisson(2)) then
         lines = [lines, string_type("identical materials: one Love table, c = 2 c1")]
      else
         lines = [lines, string_type("two elastic bodies: one Love table, c = c1 + c2")]
      end if
      lines = [lines, string_type("interface and penalty springs: an exact diagonal compliance 3/k = "//es(s/cself)// &
         " of a pixel's self-compliance")]
      if (options%boundary == BOUNDARY_PERIODIC) lines = [lines, periodic_note(problem%np, SOLVER_INCREMENTAL)]
      if (options%plastic) then
         lines = [lines, string_type("plastic cap H = "//sig_str(options%hardness, 4)//" GPa: a contact reaching "// &
            "H d^2 is an event; it leaves the elastic set (the factor shrinks) and its fixed force joins the gaps")]
      else
         lines = [lines, string_type("no plastic cap: pressures are elastic, n_above_hardness counts the pixels "// &
            "above the hardness (--plastic caps them)")]
      end if
      if (all(problem%lower == problem%lower(1, 1))) lines = [lines, string_type("lower surface flat")]
      if (all(problem%upper == problem%upper(1, 1))) lines = [lines, string_type("upper surface flat")]
   contains
      !> What the periodic boundary changes, for `solver`.
      function periodic_note(np, solver) result(line)
         integer, intent(in) :: np, solver
         type(string_type) :: line
         line%s = "periodic cell of "//int_str(np)//" x "//int_str(np)//" pixels: the Love kernel summed over "// &
            "all images (zero-mean displacements; approach = fall of the mean gap)"
         if (solver == SOLVER_CG) then
            line%s = line%s//"; cyclic transforms of "//int_str(np)//"^2, no padding (the free boundary's are "// &
               int_str(2*np)//"^2)"
         else
            line%s = line%s//"; the event path and its checks as for the free boundary, on the periodic table"
         end if
      end function periodic_note

      !> es9.2 without blanks, as the summary has always printed these ratios.
      function es(x) result(text)
         real(dp), intent(in) :: x
         character(len=:), allocatable :: text
         text = sig_str(x, 3)
      end function es
   end function solver_notes

   !> What the solver did and checked, for the summary: the model notes, then the
   !> solver's own lines, labelled, from the diagnostics it returned (its own type).
   function report_lines(problem, options, res) result(lines)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(in) :: res
      type(report_line), allocatable :: lines(:)
      type(string_type), allocatable :: model(:)
      integer :: k
      allocate(lines(0))
      if (.not. allocated(res%diagnostics)) return
      select type (d => res%diagnostics)
      type is (cg_diagnostics)
         model = model_notes(problem, options)
         do k = 1, size(model)
            call add("model", model(k)%s)
         end do
         if (options%plastic .and. size(res%states) > 0) then
            if (all(res%states%n_plastic == 0)) call add("model", "no pixel reached the hardness: the cap left "// &
               "every load one elastic solve, with no plastic bookkeeping")
         end if
         do k = 1, size(res%states)
            call add("cg", cg_line(res%states(k), d%states(k)))
         end do
      type is (event_path_diagnostics)
         model = model_notes(problem, options)
         do k = 1, size(model)
            call add("model", model(k)%s)
         end do
         if (options%plastic .and. allocated(res%step_plastic)) then
            if (all(res%step_plastic == 0)) call add("model", "no pixel reached the hardness: no plastic event, "// &
               "the elastic path with one more comparison per contact and step")
         end if
         call add("checked", "every pixel by FFT convolution at the end: "// &
            int_str(d%missed_final_check)//" penetrating (deepest "//sig_str(d%max_penetration, 2)// &
            " nm); "//int_str(d%releases)//" releases; "//int_str(d%evaluations)// &
            " exact pixel evaluations; exact re-solve differs by "//sig_str(d%final_check_difference, 2))
         call add("search", int_str(d%fft_steps)//" of "//int_str(res%nsteps)// &
            " steps by full-field FFT, the others by the gap bound (--event-search "//trim(options%event_search)//")")
         call add("cache", int_str(d%cache_hits)//" contacts bordered from the candidate "// &
            "cache, "//int_str(d%cache_misses)//" by their own triangular solves; "//int_str(d%cache_refills)// &
            " refills ("//int_str(d%cache_columns)//" columns by BLAS-3 solves)")
      type is (legacy_diagnostics)
         call add("checked", int_str(d%missed_during_run)//" contacts found late by the candidate search, "// &
            int_str(d%missed_final_check)//" found by the final check of all pixels; exact re-solve differs by "// &
            sig_str(d%final_check_difference, 2))
         call add("TRFACT", "condition estimate "//sig_str(d%condition, 2)// &
            " (LAPACK dlacn2): relative errors up to about "//sig_str(epsilon(1.0_dp)*d%condition, 1))
         if (epsilon(1.0_dp)*d%condition > 1.0e-8_dp) call add("warning", "the stiff springs and rigid body cost "// &
            "the legacy solver digits; the incremental solver is immune (doc/stability.md)")
      end select
   contains
      subroutine add(label, text)
         character(len=*), intent(in) :: label, text
         lines = [lines, report_line(label, text)]
      end subroutine add

      !> One state's line of the cg solver's work: by approach in the gap variables, by
      !> load otherwise (with the plastic rounds under the cap).
      function cg_line(st, work) result(text)
         type(load_state), intent(in) :: st
         type(cg_state_diagnostics), intent(in) :: work
         character(len=:), allocatable :: text
         if (by_gap_variables(options)) then
            text = "approach "//sig_str(st%approach, 6)//" nm: "//count_text(work%iterations, "iteration")//", residual "// &
               sig_str(work%residual, 2)//" (force balance, as a gap over the height range)"
            return
         end if
         text = "load "//sig_str(st%load, 6)//" nN: "//count_text(work%iterations, "iteration")//", residual "// &
            sig_str(work%residual, 2)//", penetration "//sig_str(work%penetration, 2)//" nm, |gap| on contact "// &
            sig_str(work%contact_gap, 2)//" nm, load error "//sig_str(work%load_error, 2)
         if (options%plastic) text = text//", in "//int_str(work%plastic_rounds)//" round"// &
            trim(merge("s", " ", work%plastic_rounds /= 1))//" of the plastic set"
      end function cg_line
   end function report_lines
end module femcod_solver
