!> Wall-clock time for the solvers' timing reports.
module femcod_clock
   use femcod_kinds, only: dp, i8
   implicit none
   private
   public :: wall_clock

contains

   !> Seconds since an arbitrary origin (system_clock).
   subroutine wall_clock(t)
      real(dp), intent(out) :: t
      integer(i8) :: count, rate
      call system_clock(count, rate)
      t = real(count, dp)/real(rate, dp)
   end subroutine wall_clock
end module femcod_clock
