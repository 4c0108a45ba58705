!> What `femcod run` gives its solver to report through (model/femcod_observer): progress
!> lines on standard error with an estimate of the time left, checkpoints written to
!> PREFIX.ckpt.h5, and the stop signals.
module femcod_run_observer
   use, intrinsic :: iso_fortran_env, only: error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: sig_str, int_str
   use femcod_process, only: stop_signal
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: contact_options, requested_states, SOLVER_LEGACY, SOLVER_CG
   use femcod_observer, only: solver_observer
   use femcod_state_visitor, only: visitable
   use femcod_checkpoint, only: write_checkpoint
   use femcod_contact_result, only: load_state
   use femcod_files, only: temporary_name
   use femcod_results_hdf5, only: stream_gap_map
   implicit none
   private
   public :: run_observer

   !> Progress lines on standard error and checkpoints to PREFIX.ckpt.h5, for one deck.
   type, extends(solver_observer) :: run_observer
      logical :: quiet = .false.
      !> Seconds of the last progress line.
      real(dp) :: last_report = 0
      !> What the run aims at, for the estimate of the time left: contacts, the largest
      !> requested load (nN, 0 if none), and how the cost grows with the contacts (n^3
      !> for the incremental solver, n^4 for the legacy one).
      integer :: target_contacts = 0
      real(dp) :: target_load = 0, growth = 3
      !> What a progress step is: "event" (the event solvers), "load" or "approach" (cg's
      !> states, of `states` asked).
      character(len=:), allocatable :: step_word
      integer :: states = 0
      !> Where checkpoints go; whether a failure to write one was reported already, and
      !> whether one was stored.
      character(len=:), allocatable :: checkpoint_path
      logical :: warned = .false., stored = .false.
      !> The temporary of PREFIX.h5 the solved states' gap maps go to (stream_gap_map),
      !> whether the run has begun it (start_result_file; no map goes out before),
      !> which states' maps are there, and whether writing one failed (the maps then stay
      !> in memory, and the writer at the end reports the disk's error).
      character(len=:), allocatable :: stream_path
      logical :: stream_started = .false., stream_failed = .false.
      logical, allocatable :: gap_in_file(:)
   contains
      procedure :: configure => configure_observer
      procedure :: progress => report_progress
      procedure :: checkpoint => store_checkpoint
      procedure :: state_solved => stream_state
      procedure :: stop_requested => signal_arrived
   end type run_observer

contains

   !> The progress and checkpoint observer of one run: what it aims at (contacts, the
   !> largest load), how its cost grows, what a step is called, where checkpoints go.
   subroutine configure_observer(self, prefix, problem, options, quiet)
      class(run_observer), intent(inout) :: self
      character(len=*), intent(in) :: prefix
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      logical, intent(in) :: quiet
      self%quiet = quiet
      self%target_contacts = problem%maxcont
      if (options%max_contacts > 0) self%target_contacts = min(options%max_contacts, problem%np**2)
      if (size(options%loads) > 0) self%target_load = maxval(options%loads)
      self%growth = merge(4.0_dp, 3.0_dp, options%solver == SOLVER_LEGACY)
      self%step_word = "event"
      if (options%solver == SOLVER_CG) then
         self%step_word = trim(merge("approach", "load    ", size(options%approaches) > 0))
         self%states = requested_states(options)
      end if
      self%checkpoint_path = prefix//".ckpt.h5"
      self%stream_path = temporary_name(prefix//".h5")
   end subroutine configure_observer

   !> A progress line on standard error at most every 5 s, with an estimate of the time
   !> left from the cost model: a run to n contacts costs ~ n**growth; with a load
   !> target, the fraction of the load reached bounds the fraction of contacts.
   subroutine report_progress(self, step, contacts, load, elapsed)
      class(run_observer), intent(inout) :: self
      integer, intent(in) :: step, contacts
      real(dp), intent(in) :: load, elapsed
      real(dp) :: fraction, left
      character(len=:), allocatable :: estimate
      if (self%quiet .or. elapsed - self%last_report < 5) return
      self%last_report = elapsed
      fraction = real(contacts, dp)/max(self%target_contacts, 1)
      if (self%target_load > 0) fraction = max(fraction, min(load/self%target_load, 1.0_dp))
      estimate = ""
      if (fraction > 0 .and. fraction < 1) then
         left = elapsed*(fraction**(-self%growth) - 1)
         estimate = ", about "//sig_str(left, 2)//" s left (cost ~ contacts^"//int_str(nint(self%growth))//")"
      end if
      if (.not. allocated(self%step_word)) self%step_word = "event"
      if (self%step_word == "event") then
         write(error_unit, '(a)') "femcod: event "//int_str(step)//", "//int_str(contacts)//" contacts, load "// &
            sig_str(load, 5)//" nN, "//sig_str(elapsed, 3)//" s elapsed"//estimate
      else
         write(error_unit, '(a)') "femcod: "//self%step_word//" "//int_str(step)//" of "//int_str(self%states)// &
            " solved, "//int_str(contacts)//" contacts, load "//sig_str(load, 5)//" nN, "//sig_str(elapsed, 3)// &
            " s elapsed"
      end if
      flush(error_unit)
   end subroutine report_progress

   !> Store the solver's state in PREFIX.ckpt.h5; a failure to write is reported once and
   !> the run goes on.
   subroutine store_checkpoint(self, problem, options, state)
      class(run_observer), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      class(visitable), intent(inout) :: state
      type(status_type) :: st
      call write_checkpoint(self%checkpoint_path, problem, options, state, st)
      self%stored = self%stored .or. st%code == 0
      if (st%code /= 0 .and. .not. self%warned) then
         write(error_unit, '(a)') "femcod: warning: checkpoint not written: "//st%message
         flush(error_unit)
         self%warned = .true.
      end if
   end subroutine store_checkpoint

   !> State k of n is solved: its gap map (8 bytes a pixel) goes to the result file
   !> being built and leaves memory, so that a run of many states holds one map.
   subroutine stream_state(self, k, n, state)
      class(run_observer), intent(inout) :: self
      integer, intent(in) :: k, n
      type(load_state), intent(inout) :: state
      type(status_type) :: st
      if (.not. allocated(state%gap) .or. .not. self%stream_started .or. self%stream_failed) return
      if (.not. allocated(self%gap_in_file)) allocate(self%gap_in_file(n), source=.false.)
      call stream_gap_map(self%stream_path, k, n, state%gap, st)
      if (st%code /= 0) then
         self%stream_failed = .true.
         return
      end if
      self%gap_in_file(k) = .true.
      deallocate(state%gap)
   end subroutine stream_state

   !> A stop signal (SIGTERM, SIGINT, SIGUSR1) has arrived.
   logical function signal_arrived(self)
      class(run_observer), intent(inout) :: self
      signal_arrived = stop_signal() /= 0
   end function signal_arrived
end module femcod_run_observer
