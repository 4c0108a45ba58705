!> The program's version (printed by `femcod --version`, stored in results). fpm.toml's `version` is the
!> one place it is decided: this copy, mpi/fpm.toml's and the Python package's follow it (python/tests/test_version.py).
module femcod_about
   implicit none
   private
   public :: FEMCOD_VERSION

   character(len=*), parameter :: FEMCOD_VERSION = "0.2.0"
end module femcod_about
