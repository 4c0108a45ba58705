!> The program's version (printed by `femcod --version`, stored in results).
module femcod_about
   implicit none
   private
   public :: FEMCOD_VERSION

   character(len=*), parameter :: FEMCOD_VERSION = "0.1.0"
end module femcod_about
