!> FFTW 3 MPI bindings (the library's own Fortran 2003 interface, fftw3-mpi.f03, which
!> includes the serial fftw3.f03: use this module or femcod_fftw in one scope, not both),
!> and the one place femcod-mpi starts and stops FFTW's MPI transforms and sets their
!> threads: the program calls start_distributed_fftw once before any plan is made.
module femcod_fftw_mpi
   use, intrinsic :: iso_c_binding
   implicit none
   public
#include "fftw3-mpi.f03"

contains

   !> FFTW's threads and MPI transforms, double and float32, started once per process;
   !> every plan made afterwards runs on `threads` threads (OpenMP's, per rank). An empty
   !> `message` on success, else what would not start.
   subroutine start_distributed_fftw(threads, message)
      integer, intent(in) :: threads
      character(len=:), allocatable, intent(out) :: message
      message = ""
      if (fftw_init_threads() == 0) then
         message = "FFTW's threads would not start"
         return
      end if
      call fftw_mpi_init()
      if (fftwf_init_threads() == 0) then
         message = "FFTW's float32 threads would not start"
         return
      end if
      call fftwf_mpi_init()
      call fftw_plan_with_nthreads(int(threads, c_int))
      call fftwf_plan_with_nthreads(int(threads, c_int))
   end subroutine start_distributed_fftw

   !> FFTW's MPI state released (before MPI_Finalize).
   subroutine stop_distributed_fftw()
      call fftw_mpi_cleanup()
   end subroutine stop_distributed_fftw
end module femcod_fftw_mpi
