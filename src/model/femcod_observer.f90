!> How a solver reports while it runs, without doing I/O itself: it calls the
!> type-bound procedures of an observer object, which carries its own context (where
!> to write a checkpoint, when it last printed a progress line). The base type does
!> nothing; a program extends it (cli/femcod_run_observer's run_observer, the studies' progress).
module femcod_observer
   use femcod_kinds, only: dp
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: contact_options
   use femcod_state_visitor, only: visitable
   use femcod_contact_result, only: load_state
   implicit none
   private
   public :: solver_observer

   !> An observer that ignores everything: the default of every solver.
   type :: solver_observer
   contains
      !> After every step of an event path (or every load of the cg solver).
      procedure :: progress => ignore_progress
      !> Every options%checkpoint_interval seconds, with the solver's complete state.
      procedure :: checkpoint => ignore_checkpoint
      !> After each state of the cg solver is recorded: an observer may take the state's
      !> NP x NP maps out of memory (femcod run writes them to the result file it builds).
      procedure :: state_solved => keep_state
      !> Asked between steps (iterations of the cg solver): should the solver stop now?
      !> The incremental solver then hands over a checkpoint first; every solver returns
      !> STATUS_INTERRUPTED.
      procedure :: stop_requested => never_stop
   end type solver_observer

contains

   !> step, contacts carrying load, total load (nN) and seconds since the solve began.
   subroutine ignore_progress(self, step, contacts, load, elapsed)
      class(solver_observer), intent(inout) :: self
      integer, intent(in) :: step, contacts
      real(dp), intent(in) :: load, elapsed
   end subroutine ignore_progress

   !> The state that continues the run exactly where it is, with the problem and the
   !> options it belongs to (a checkpoint stores all three).
   subroutine ignore_checkpoint(self, problem, options, state)
      class(solver_observer), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      class(visitable), intent(inout) :: state
   end subroutine ignore_checkpoint

   !> State k of n (the target's place in the options, not the order of solving), with
   !> its gap map when the solver has one. The base keeps everything.
   subroutine keep_state(self, k, n, state)
      class(solver_observer), intent(inout) :: self
      integer, intent(in) :: k, n
      type(load_state), intent(inout) :: state
   end subroutine keep_state

   logical function never_stop(self)
      class(solver_observer), intent(inout) :: self
      never_stop = .false.
   end function never_stop
end module femcod_observer
