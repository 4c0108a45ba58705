!> Help for the commands: whether the arguments ask for it, and printing the lines an
!> option table makes (femcod_options%option_help).
module femcod_help
   use, intrinsic :: iso_fortran_env, only: output_unit
   use femcod_strings, only: string_type
   implicit none
   private
   public :: help_requested, print_lines

contains

   !> Whether any argument is --help or -h.
   pure logical function help_requested(args)
      type(string_type), intent(in) :: args(:)
      integer :: k
      help_requested = .false.
      do k = 1, size(args)
         if (args(k)%s == "--help" .or. args(k)%s == "-h") help_requested = .true.
      end do
   end function help_requested

   !> Each line on standard output.
   subroutine print_lines(lines)
      type(string_type), intent(in) :: lines(:)
      integer :: k
      do k = 1, size(lines)
         write(output_unit, '(a)') lines(k)%s
      end do
   end subroutine print_lines
end module femcod_help
