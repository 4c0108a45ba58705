!> A portable, reproducible random stream: L'Ecuyer's MRG32k3a combined multiple
!> recursive generator, computed exactly in double precision (the same numbers on
!> every machine and compiler), with Box-Muller normal deviates.
module femcod_random
   use femcod_kinds, only: dp
   implicit none
   private
   public :: random_stream, seed_stream, uniform, normal

   real(dp), parameter :: m1 = 4294967087.0_dp, m2 = 4294944443.0_dp
   real(dp), parameter :: a12 = 1403580.0_dp, a13n = 810728.0_dp, a21 = 527612.0_dp, a23n = 1370589.0_dp
   real(dp), parameter :: norm = 2.328306549295727688e-10_dp
   real(dp), parameter :: pi = acos(-1.0_dp)

   !> Generator state.
   type :: random_stream
      real(dp) :: s1(3) = 12345, s2(3) = 12345
   end type random_stream

contains

   !> Seed the stream from an integer (any value >= 0); distinct seeds give distinct streams.
   pure subroutine seed_stream(stream, seed)
      type(random_stream), intent(out) :: stream
      integer, intent(in) :: seed
      integer :: k
      real(dp) :: u
      stream%s1 = [12345.0_dp + mod(abs(seed), 100000), 12345.0_dp, 12345.0_dp + mod(abs(seed)/100000, 100000)]
      stream%s2 = [12345.0_dp, 12345.0_dp + mod(abs(seed), 99991), 12345.0_dp]
      do k = 1, 20
         call uniform(stream, u)
      end do
   end subroutine seed_stream

   !> A uniform deviate in (0, 1).
   pure subroutine uniform(stream, u)
      type(random_stream), intent(inout) :: stream
      real(dp), intent(out) :: u
      real(dp) :: p1, p2
      p1 = a12*stream%s1(2) - a13n*stream%s1(1)
      p1 = p1 - aint(p1/m1)*m1
      if (p1 < 0) p1 = p1 + m1
      stream%s1 = [stream%s1(2), stream%s1(3), p1]
      p2 = a21*stream%s2(3) - a23n*stream%s2(1)
      p2 = p2 - aint(p2/m2)*m2
      if (p2 < 0) p2 = p2 + m2
      stream%s2 = [stream%s2(2), stream%s2(3), p2]
      if (p1 > p2) then
         u = (p1 - p2)*norm
      else
         u = (p1 - p2 + m1)*norm
      end if
   end subroutine uniform

   !> A standard normal deviate (Box-Muller).
   pure subroutine normal(stream, z)
      type(random_stream), intent(inout) :: stream
      real(dp), intent(out) :: z
      real(dp) :: u1, u2
      call uniform(stream, u1)
      call uniform(stream, u2)
      z = sqrt(-2*log(u1))*cos(2*pi*u2)
   end subroutine normal
end module femcod_random
