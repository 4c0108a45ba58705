!> Closed-form solutions the thesis compares against (lengths nm, loads nN, moduli GPa).
module femcod_analytic
   use femcod_kinds, only: dp
   implicit none
   private
   public :: hertz_approach, segedin_sphere, flat_punch_approach

contains

   !> Hertz, eq. 4.14: approach of a sphere of radius r under load f, E* the
   !> effective modulus (eq. 4.13): delta = (9 f^2 / (16 r E*^2))^(1/3).
   pure real(dp) function hertz_approach(f, r, estar)
      real(dp), intent(in) :: f, r, estar
      hertz_approach = (9*f**2/(16*r*estar**2))**(1.0_dp/3)
   end function hertz_approach

   !> Segedin's rigid sphere (not paraboloid) on a half-space: contact radius a and
   !> approach delta at load f, from F = E*/2 [(a^2+R^2) ln((R+a)/(R-a)) - 2aR] by
   !> bisection, delta = (a/2) ln((R+a)/(R-a)).
   pure subroutine segedin_sphere(f, r, estar, a, delta)
      real(dp), intent(in) :: f, r, estar
      real(dp), intent(out) :: a, delta
      real(dp) :: lo, hi
      integer :: it
      lo = 0
      hi = r*(1 - 1.0e-12_dp)
      do it = 1, 200
         a = (lo + hi)/2
         if (estar/2*((a*a + r*r)*log((r + a)/(r - a)) - 2*a*r) < f) then
            lo = a
         else
            hi = a
         end if
      end do
      delta = a/2*log((r + a)/(r - a))
   end subroutine segedin_sphere

   !> Rigid flat circular punch of radius r, eq. 4.10: delta = f (1 - nu^2)/(2 r E).
   pure real(dp) function flat_punch_approach(f, r, young, poisson)
      real(dp), intent(in) :: f, r, young, poisson
      flat_punch_approach = f*(1 - poisson**2)/(2*r*young)
   end function flat_punch_approach
end module femcod_analytic
