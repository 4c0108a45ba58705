!> Working precision of femcod. Every real computed with is `real(dp)`; `sp` stores
!> what the fixed-load solver keeps in float32 where its round-off cannot reach the
!> answer (transforms of search directions, the previous gaps, the table of direct
!> corrections: femcod_convolution, femcod_cg).
module femcod_kinds
   use, intrinsic :: iso_fortran_env, only: real32, real64, int64
   implicit none
   private
   public :: dp, sp, i8

   !> Double precision (IEEE binary64), the working precision.
   integer, parameter :: dp = real64
   !> Single precision (IEEE binary32), for storage only.
   integer, parameter :: sp = real32
   !> 64-bit integer for byte counts and large products.
   integer, parameter :: i8 = int64
end module femcod_kinds
