!> Richardson extrapolation (thesis eq. 4.12) and power-law fits.
!>
!> For meshes h1 > h2 > h3 refined by a constant ratio r = h1/h2 = h2/h3 and a value
!> converging as phi = phi0 + C h**p:
!>     p    = ln((phi1 - phi2)/(phi2 - phi3)) / ln(r)
!>     phi0 = (r**p phi2 - phi1)/(r**p - 1)             (eq. 4.12 with h1/h2 = r)
!> With a known limit phi0 and two meshes: p = ln((phi1 - phi0)/(phi2 - phi0))/ln(r).
module femcod_richardson
   use femcod_kinds, only: dp
   implicit none
   private
   public :: convergence_rate, convergence_rate_known_limit, richardson_extrapolate, power_law_fit

contains

   !> Rate of convergence from three meshes refined by `ratio`.
   pure real(dp) function convergence_rate(phi1, phi2, phi3, ratio)
      real(dp), intent(in) :: phi1, phi2, phi3, ratio
      convergence_rate = log((phi1 - phi2)/(phi2 - phi3))/log(ratio)
   end function convergence_rate

   !> Rate of convergence from two meshes and the exact limit.
   pure real(dp) function convergence_rate_known_limit(phi1, phi2, phi0, ratio)
      real(dp), intent(in) :: phi1, phi2, phi0, ratio
      convergence_rate_known_limit = log((phi1 - phi0)/(phi2 - phi0))/log(ratio)
   end function convergence_rate_known_limit

   !> Extrapolated value from a coarse and a fine mesh (ratio h_coarse/h_fine) at rate p.
   pure real(dp) function richardson_extrapolate(phi_coarse, phi_fine, ratio, p)
      real(dp), intent(in) :: phi_coarse, phi_fine, ratio, p
      richardson_extrapolate = (ratio**p*phi_fine - phi_coarse)/(ratio**p - 1)
   end function richardson_extrapolate

   !> Least-squares fit of y = prefactor * x**exponent in log-log (positive x, y only).
   pure subroutine power_law_fit(x, y, exponent, prefactor)
      real(dp), intent(in) :: x(:), y(:)
      real(dp), intent(out) :: exponent, prefactor
      real(dp) :: sx, sy, sxx, sxy
      integer :: k, m
      sx = 0; sy = 0; sxx = 0; sxy = 0
      m = 0
      do k = 1, size(x)
         if (x(k) <= 0 .or. y(k) <= 0) cycle
         m = m + 1
         sx = sx + log(x(k))
         sy = sy + log(y(k))
         sxx = sxx + log(x(k))**2
         sxy = sxy + log(x(k))*log(y(k))
      end do
      exponent = 0
      prefactor = 0
      if (m < 2) return
      exponent = (m*sxy - sx*sy)/(m*sxx - sx*sx)
      prefactor = exp((sy - exponent*sx)/m)
   end subroutine power_law_fit
end module femcod_richardson
