!> FFTW 3 bindings (the library's own Fortran 2003 interface, fftw3.f03).
module femcod_fftw
   use, intrinsic :: iso_c_binding
   implicit none
   public
#include "fftw3.f03"
end module femcod_fftw
