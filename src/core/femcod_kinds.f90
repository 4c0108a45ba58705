!> Working precision of femcod. Every real in the program is `real(dp)`.
module femcod_kinds
   use, intrinsic :: iso_fortran_env, only: real64, int64
   implicit none
   private
   public :: dp, i8

   !> Double precision (IEEE binary64), the only working precision.
   integer, parameter :: dp = real64
   !> 64-bit integer for byte counts and large products.
   integer, parameter :: i8 = int64
end module femcod_kinds
