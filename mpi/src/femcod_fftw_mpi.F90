!> FFTW 3 MPI bindings (the library's own Fortran 2003 interface, fftw3-mpi.f03, which
!> includes the serial fftw3.f03: use this module or femcod_fftw in one scope, not both).
module femcod_fftw_mpi
   use, intrinsic :: iso_c_binding
   implicit none
   public
#include "fftw3-mpi.f03"
end module femcod_fftw_mpi
