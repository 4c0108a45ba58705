!> The Love kernel of the Boussinesq half-space (thesis section 4.2.1, eq. 4.4): the one
!> influence table every solver uses.
!>
!> Love (1929): a uniform pressure with total load P on a d x d pixel displaces the
!> half-space surface at pixel offset (p, q) by
!>     u = (1 - nu**2)/(pi E d) * P * love_influence(p, q)
!> with the dimensionless four-corner sum (eq. 4.4, in pixel units, h = 1/2)
!>     I = f(p+h, q+h) - f(p+h, q-h) - f(p-h, q+h) + f(p-h, q-h),
!>     f(a, b) = a asinh(b/|a|) + b asinh(a/|b|)   (a term is 0 when its factor is 0).
!> The absolute values make f odd in a and in b; without them I(0,0) would be 0
!> instead of 4 ln(1 + sqrt 2). The four-corner sum cancels at large offsets; beyond
!> rho = 20 pixels femcod uses the far-field expansion of the pixel average of 1/r,
!>     I = 1/rho + 1/(24 rho**3) + (119 p**2 q**2 rho**2 - 7 (p**6 + q**6))/(1920 rho**11)
!>         + 3 p**2 q**2/(256 rho**11) - 3/(7168 rho**7) + O(rho**-9),
!> which agrees with a 50-digit evaluation of the exact sum to 1e-14 there, while the
!> exact sum in double loses up to 1e-10 at rho = 700 (doc/verification.md).
module femcod_love
   use femcod_kinds, only: dp
   implicit none
   private
   public :: love_influence, love_influence_exact, love_influence_far, offset_table, surface_compliance, &
      composite_modulus
   public :: FAR_FIELD_RADIUS

   !> Offsets (in pixels) from which the far-field expansion is used.
   real(dp), parameter :: FAR_FIELD_RADIUS = 20

contains

   !> Composite modulus E* of two elastic bodies: 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 (GPa).
   pure real(dp) function composite_modulus(young, poisson)
      real(dp), intent(in) :: young(2), poisson(2)
      composite_modulus = 1/((1 - poisson(1)**2)/young(1) + (1 - poisson(2)**2)/young(2))
   end function composite_modulus

   !> Surface compliance factor (1 - nu**2)/(pi E d) in nm/nN for E in GPa, d in nm.
   pure real(dp) function surface_compliance(young, poisson, pixel)
      real(dp), intent(in) :: young, poisson, pixel
      surface_compliance = (1 - poisson**2)/(acos(-1.0_dp)*young*pixel)
   end function surface_compliance

   !> Dimensionless Love influence at integer pixel offset (p, q); evaluated at
   !> (min(|p|,|q|), max(|p|,|q|)) so that the symmetries of I hold bit for bit.
   elemental real(dp) function love_influence(p, q)
      integer, intent(in) :: p, q
      real(dp) :: a, b
      a = real(min(abs(p), abs(q)), dp)
      b = real(max(abs(p), abs(q)), dp)
      if (a*a + b*b >= FAR_FIELD_RADIUS**2) then
         love_influence = love_influence_far(a, b)
      else
         love_influence = love_influence_exact(a, b)
      end if
   end function love_influence

   !> The four-corner sum of eq. 4.4 at offset (x, y) in pixels.
   elemental real(dp) function love_influence_exact(x, y)
      real(dp), intent(in) :: x, y
      real(dp), parameter :: h = 0.5_dp
      love_influence_exact = f(x + h, y + h) - f(x + h, y - h) - f(x - h, y + h) + f(x - h, y - h)
   contains
      pure real(dp) function f(a, b)
         real(dp), intent(in) :: a, b
         f = 0
         if (a /= 0) f = f + a*asinh(b/abs(a))
         if (b /= 0) f = f + b*asinh(a/abs(b))
      end function f
   end function love_influence_exact

   !> Far-field expansion of the pixel average of 1/r at offset (x, y) in pixels.
   elemental real(dp) function love_influence_far(x, y)
      real(dp), intent(in) :: x, y
      real(dp) :: x2, y2, r2, r
      x2 = x*x
      y2 = y*y
      r2 = x2 + y2
      r = sqrt(r2)
      love_influence_far = 1/r + 1/(24*r*r2) + ((119*x2*y2*r2 - 7*(x2**3 + y2**3))/1920 + 3*x2*y2/256)/(r*r2**5) &
         - 3/(7168*r*r2**3)
   end function love_influence_far

   !> The translation-invariant table I(p, q), p, q = 0 .. np-1 (I is even in p and q,
   !> so one quadrant serves every pair of pixels of an NP x NP grid). Entries are
   !> independent, so the OpenMP loop gives the same bits for any number of threads.
   function offset_table(np) result(table)
      integer, intent(in) :: np
      real(dp) :: table(0:np - 1, 0:np - 1)
      integer :: p, q
      !$omp parallel do schedule(dynamic, 8) private(p)
      do q = 0, np - 1
         do p = 0, np - 1
            table(p, q) = love_influence(p, q)
         end do
      end do
      !$omp end parallel do
   end function offset_table
end module femcod_love
