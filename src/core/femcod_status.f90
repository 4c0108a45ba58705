!> Status carried by every fallible routine. The numerical core never stops the
!> program: it sets a status and returns; programs in app/ turn the code into an
!> exit code (doc/exit-codes in README).
module femcod_status
   implicit none
   private
   public :: status_type, set_error, status_ok
   public :: STATUS_OK_CODE, STATUS_USAGE, STATUS_BAD_INPUT, STATUS_NUMERICAL, STATUS_IO, STATUS_INTERRUPTED

   !> Success.
   integer, parameter :: STATUS_OK_CODE = 0
   !> Wrong command-line usage.
   integer, parameter :: STATUS_USAGE = 2
   !> Bad input data (deck, matrix file, option value).
   integer, parameter :: STATUS_BAD_INPUT = 3
   !> Numerical failure (singular system, allocation of the workspace, ...).
   integer, parameter :: STATUS_NUMERICAL = 4
   !> Input/output failure (cannot write a result file, ...).
   integer, parameter :: STATUS_IO = 5
   !> Stopped by a stop signal (SIGTERM, SIGINT, SIGUSR1) at the observer's request; the
   !> program exits with 128 + the signal's number.
   integer, parameter :: STATUS_INTERRUPTED = 6

   !> A status: `code` is 0 on success, otherwise one of the codes above,
   !> `message` says what went wrong and where.
   type :: status_type
      integer :: code = STATUS_OK_CODE
      character(len=:), allocatable :: message
   end type status_type

contains

   !> Record an error with its code and message.
   pure subroutine set_error(status, code, message)
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      character(len=*), intent(in) :: message
      status%code = code
      status%message = message
   end subroutine set_error

   !> True when the status carries no error.
   pure logical function status_ok(status)
      type(status_type), intent(in) :: status
      status_ok = status%code == STATUS_OK_CODE
   end function status_ok
end module femcod_status
