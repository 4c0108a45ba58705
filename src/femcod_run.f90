!> `femcod run` (placeholder until the solvers land: reads and validates the deck).
module femcod_run
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_status, only: status_type
   use femcod_deck, only: deck_type, read_deck
   use femcod_strings, only: string_type
   implicit none
   private
   public :: run_command
contains
   subroutine run_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(deck_type) :: deck
      type(status_type) :: status
      code = 0
      if (size(args) < 1) then
         code = 2
         return
      end if
      call read_deck(args(1)%s, deck, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod: "//status%message
         code = status%code
      end if
   end subroutine run_command
end module femcod_run
