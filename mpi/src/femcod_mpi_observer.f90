!> The observer femcod-mpi gives its solver: a stop signal (SIGTERM, SIGINT, SIGUSR1,
!> caught by femcod_process) asks every rank to stop; the solver sums the requests, so
!> that all ranks stop at the same iteration.
module femcod_mpi_observer
   use femcod_observer, only: solver_observer
   use femcod_process, only: stop_signal
   implicit none
   private
   public :: signal_observer

   type, extends(solver_observer) :: signal_observer
   contains
      procedure :: stop_requested => signal_arrived
   end type signal_observer

contains

   logical function signal_arrived(self)
      class(signal_observer), intent(inout) :: self
      signal_arrived = stop_signal() /= 0
   end function signal_arrived
end module femcod_mpi_observer
