!> A portable, reproducible random stream: L'Ecuyer's MRG32k3a combined multiple
!> recursive generator, computed exactly in double precision (the same numbers on
!> every machine and compiler), with Box-Muller normal deviates (two uniforms each).
!> advance_stream jumps a stream ahead by any number of uniforms in O(log n) (the
!> recursions' matrices raised to the n-th power modulo m1 and m2; L'Ecuyer, Simard,
!> Chen and Kelton, Oper. Res. 50, 2002, 1073-1075), so that parts of one stream can be
!> drawn on different processes: femcod-mpi's ranks each draw their own columns of a
!> surface's spectrum, as one core draws them all.
module femcod_random
   use, intrinsic :: iso_fortran_env, only: int64
   use femcod_kinds, only: dp
   implicit none
   private
   public :: random_stream, seed_stream, uniform, normal, advance_stream

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

   !> The stream moved on by n uniforms (n >= 0), as n calls of `uniform` would.
   pure subroutine advance_stream(stream, n)
      type(random_stream), intent(inout) :: stream
      integer(int64), intent(in) :: n
      integer(int64), parameter :: im1 = 4294967087_int64, im2 = 4294944443_int64
      integer(int64) :: a1(3, 3), a2(3, 3)
      a1 = reshape([0_int64, 0_int64, im1 - 810728_int64, 1_int64, 0_int64, 1403580_int64, 0_int64, 1_int64, &
         0_int64], [3, 3])
      a2 = reshape([0_int64, 0_int64, im2 - 1370589_int64, 1_int64, 0_int64, 0_int64, 0_int64, 1_int64, &
         527612_int64], [3, 3])
      stream%s1 = real(apply(power(a1, n, im1), int(stream%s1, int64), im1), dp)
      stream%s2 = real(apply(power(a2, n, im2), int(stream%s2, int64), im2), dp)
   contains
      !> a b mod m for 0 <= a, b < m < 2^32, exactly in 64 bits (b in 16-bit halves).
      pure integer(int64) function mulmod(a, b, m)
         integer(int64), intent(in) :: a, b, m
         mulmod = mod(mod(a*(b/65536_int64), m)*65536_int64, m)
         mulmod = mod(mulmod + mod(a*mod(b, 65536_int64), m), m)
      end function mulmod

      pure function product_mod(a, b, m) result(c)
         integer(int64), intent(in) :: a(3, 3), b(3, 3), m
         integer(int64) :: c(3, 3)
         integer :: i, j, k
         do j = 1, 3
            do i = 1, 3
               c(i, j) = 0
               do k = 1, 3
                  c(i, j) = mod(c(i, j) + mulmod(a(i, k), b(k, j), m), m)
               end do
            end do
         end do
      end function product_mod

      !> a^e mod m by squaring.
      pure function power(a, e, m) result(p)
         integer(int64), intent(in) :: a(3, 3), e, m
         integer(int64) :: p(3, 3), base(3, 3), left
         integer :: i
         p = 0
         do i = 1, 3
            p(i, i) = 1
         end do
         base = a
         left = e
         do while (left > 0)
            if (mod(left, 2_int64) == 1) p = product_mod(p, base, m)
            base = product_mod(base, base, m)
            left = left/2
         end do
      end function power

      pure function apply(a, v, m) result(w)
         integer(int64), intent(in) :: a(3, 3), v(3), m
         integer(int64) :: w(3)
         integer :: i, k
         do i = 1, 3
            w(i) = 0
            do k = 1, 3
               w(i) = mod(w(i) + mulmod(a(i, k), v(k), m), m)
            end do
         end do
      end function apply
   end subroutine advance_stream
end module femcod_random
