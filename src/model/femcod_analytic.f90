!> Closed-form solutions the thesis compares against (lengths nm, loads nN, moduli GPa).
module femcod_analytic
   use femcod_kinds, only: dp
   implicit none
   private
   public :: hertz_approach, segedin_sphere, flat_punch_approach, maugis_dugdale, maugis_minimum, maugis_pull_off, &
      maugis_at_load

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
   !> The Maugis-Dugdale sphere (Maugis 1992, in Johnson's notation, Proc. R. Soc. A 453,
   !> 1997): for the transition parameter lambda = 2 sigma0 (R/(pi W K^2))^(1/3),
   !> K = 4 E*/3, and m = c/a (the outer radius of the Dugdale zone over the contact
   !> radius), the contact radius abar = a (K/(pi W R^2))^(1/3) solves
   !>   lambda abar^2/2 [sqrt(m^2-1) + (m^2-2) atan sqrt(m^2-1)]
   !>     + 4 lambda^2 abar/3 [sqrt(m^2-1) atan sqrt(m^2-1) - m + 1] = 1,
   !> and the load and penetration are
   !>   Pbar = P/(pi W R) = abar^3 - lambda abar^2 [sqrt(m^2-1) + m^2 atan sqrt(m^2-1)],
   !>   dbar = delta (K^2/(pi^2 W^2 R))^(1/3) = abar^2 - 4/3 lambda abar sqrt(m^2-1).
   pure subroutine maugis_dugdale(lambda, m, abar, pbar, dbar)
      real(dp), intent(in) :: lambda, m
      real(dp), intent(out) :: abar, pbar, dbar
      real(dp) :: s, t, qa, qb
      s = sqrt(max(m**2 - 1, 0.0_dp))
      t = atan(s)
      qa = lambda/2*(s + (m**2 - 2)*t)
      qb = 4*lambda**2/3*(s*t - m + 1)
      if (abs(qa) > 0) then
         abar = (-qb + sqrt(qb**2 + 4*qa))/(2*qa)
      else
         abar = 1/qb
      end if
      pbar = abar**3 - lambda*abar**2*(s + m**2*t)
      dbar = abar**2 - 4*lambda*abar*s/3
   end subroutine maugis_dugdale

   !> The least load of the Maugis-Dugdale curve (the pull-off force under load control,
   !> over pi W R) for lambda, and the m where it lies: the minimum over m by a scan of
   !> log(m - 1) from 1e-9 to 1e4, then golden-section search.
   pure subroutine maugis_minimum(lambda, pmin, m_at)
      real(dp), intent(in) :: lambda
      real(dp), intent(out) :: pmin, m_at
      real(dp) :: lo, hi, x1, x2, f1, f2, abar, dbar, best, step
      real(dp), parameter :: golden = 0.6180339887498949_dp
      integer :: it
      lo = log(1.0e-9_dp)
      hi = log(1.0e4_dp)
      step = (hi - lo)/400
      pmin = huge(1.0_dp)
      best = lo
      do it = 0, 400
         x1 = lo + step*it
         call maugis_dugdale(lambda, 1 + exp(x1), abar, f1, dbar)
         if (f1 < pmin) then
            pmin = f1
            best = x1
         end if
      end do
      lo = best - step
      hi = best + step
      x1 = hi - golden*(hi - lo)
      x2 = lo + golden*(hi - lo)
      call maugis_dugdale(lambda, 1 + exp(x1), abar, f1, dbar)
      call maugis_dugdale(lambda, 1 + exp(x2), abar, f2, dbar)
      do it = 1, 200
         if (f1 < f2) then
            hi = x2
            x2 = x1
            f2 = f1
            x1 = hi - golden*(hi - lo)
            call maugis_dugdale(lambda, 1 + exp(x1), abar, f1, dbar)
         else
            lo = x1
            x1 = x2
            f1 = f2
            x2 = lo + golden*(hi - lo)
            call maugis_dugdale(lambda, 1 + exp(x2), abar, f2, dbar)
         end if
      end do
      pmin = min(pmin, f1, f2)
      m_at = 1 + exp((lo + hi)/2)
   end subroutine maugis_minimum

   !> The least load of the Maugis-Dugdale curve over pi W R (maugis_minimum).
   pure real(dp) function maugis_pull_off(lambda) result(pmin)
      real(dp), intent(in) :: lambda
      real(dp) :: m_at
      call maugis_minimum(lambda, pmin, m_at)
   end function maugis_pull_off

   !> The Maugis-Dugdale state at the load pbar (above the least load) on the branch of
   !> large contacts (1 <= m <= m at the least load, where the load falls as m grows), by
   !> bisection: its contact radius and penetration (nondimensional).
   pure subroutine maugis_at_load(lambda, pbar, abar, dbar)
      real(dp), intent(in) :: lambda, pbar
      real(dp), intent(out) :: abar, dbar
      real(dp) :: lo, hi, mid, p, pmin, m_at
      integer :: it
      call maugis_minimum(lambda, pmin, m_at)
      hi = log(m_at - 1)
      lo = log(1.0e-12_dp)
      do it = 1, 200
         mid = (lo + hi)/2
         call maugis_dugdale(lambda, 1 + exp(mid), abar, p, dbar)
         if (p > pbar) then
            lo = mid
         else
            hi = mid
         end if
      end do
      call maugis_dugdale(lambda, 1 + exp((lo + hi)/2), abar, p, dbar)
   end subroutine maugis_at_load

end module femcod_analytic
