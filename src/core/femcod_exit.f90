!> Ending a program with an exit code and no extra output (used only by app/ programs;
!> the numerical core returns a status instead).
module femcod_exit
   use, intrinsic :: iso_c_binding, only: c_int
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   implicit none
   private
   public :: exit_program

   interface
      subroutine c_exit(code) bind(c, name="exit")
         import :: c_int
         integer(c_int), value :: code
      end subroutine c_exit
   end interface

contains

   !> Flush standard output and error and end the process with `code`.
   subroutine exit_program(code)
      integer, intent(in) :: code
      flush(output_unit)
      flush(error_unit)
      call c_exit(int(code, c_int))
   end subroutine exit_program
end module femcod_exit
