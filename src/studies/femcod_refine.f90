!> The thesis' third model (section 5.3): the Boussinesq solve at the image's resolution,
!> refined below the pixel by the image's own fractal parameters. No I/O.
!>
!> The model, and what it assumes:
!> - The solve at pixel d gives each contact pixel its mean pressure p_i: the elastic
!>   interaction of all contacts at scales d and above is the exact one (chapter 4).
!> - Below the pixel the surface continues the power law its PSD follows over the fit
!>   range, C(q) = C0 q^-(2+2H) (isotropic, self-affine; section 3.1's fractal model). The
!>   roughness between the pixel's wavenumber q_d = pi/d and zeta q_d (magnification zeta)
!>   has the mean square slope
!>       m2(zeta) = 2 pi int_{q_d}^{zeta q_d} q^3 C(q) dq
!>                = 2 pi C0 ((zeta q_d)^(2-2H) - q_d^(2-2H)) / (2 - 2H).
!> - Each contact pixel is a nominally flat contact at the mean pressure p_i over this
!>   finer roughness, which refines it hierarchically scale by scale. Persson's theory of
!>   that sub-problem (B. N. J. Persson, J. Chem. Phys. 115 (2001) 3840, eqs. (5) and
!>   (14); Surf. Sci. Rep. 61 (2006) 201, eq. (9)) gives the fraction of the pixel still
!>   in contact:
!>       f_i(zeta) = erf( sqrt(2) p_i / (E* sqrt(m2(zeta))) ),
!>   so the real area is d^2 sum_i f_i(zeta). At zeta = 1, f_i = 1: the solve's own area.
!>   The refinement puts a constant kappa measured on the image in place of sqrt(2): over
!>   the octaves 2d -> d and 4d -> 2d and the two octaves 4d -> d (the solves at 2d and 4d
!>   carried to the areas at d and 2d: calibrate_kappa), and for the band of N octaves
!>   below d their law in N and in the band's scale (kappa_decay, kappa_drift, band_kappa).
!> - Assumptions: the interaction between sub-pixel contacts of different pixels is that
!>   of their mean pressures (already in the solve); a pixel out of contact stays out
!>   (its sub-pixel peaks do not reach across its gap); the material stays elastic.
!>
!> Beside it, on the same PSD:
!> - Persson's theory of the whole surface at the nominal pressure p0 = F / L^2: its mean
!>   square slope from the image's spectrum over q_L = 2 pi / L .. q_d, continued by the
!>   fit's power law beyond;
!> - Richardson's extrapolation of section 4.5 from solves at d, 2d and 4d.
module femcod_refine
   use, intrinsic :: iso_c_binding, only: c_double_complex
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_strings, only: int_str, sig_str
   use femcod_convolution, only: forward_complex_transform
   implicit none
   private
   public :: surface_spectrum_of, fit_spectrum, subpixel_slope_variance, refined_fraction, persson_fraction, &
      richardson_area, magnifications, calibrate_kappa, kappa_decay, kappa_drift, band_kappa, band_edge, &
      MIN_R_SQUARED, MIN_FIT_RATIO

   real(dp), parameter :: PI = acos(-1.0_dp)
   !> A power law is accepted when log C against log q fits a line with r^2 at least this,
   !> over wavenumbers spanning at least this ratio.
   real(dp), parameter :: MIN_R_SQUARED = 0.9_dp, MIN_FIT_RATIO = 4

   !> An image's isotropic PSD and its power-law fit.
   type, public :: surface_spectrum
      !> Bin centres (1/nm, geometric) and the radially averaged PSD C(q) (nm^4), C(q)
      !> normalised so that the mean square height is 2 pi int q C(q) dq.
      real(dp), allocatable :: q(:), c(:)
      !> The Fourier modes averaged in each bin (the fit's weights: the variance of a bin's
      !> log C falls as 1/modes).
      integer, allocatable :: modes(:)
      !> The mean square slope of the image over the disc |q| <= q_d = pi/d (2 pi int q^3 C dq).
      real(dp) :: slope_variance = 0
      !> The fit range (1/nm), the points in it, C(q) = prefactor q^-(2+2 hurst), r^2.
      real(dp) :: q_low = 0, q_high = 0, prefactor = 0, hurst = 0, r_squared = 0
      integer :: points = 0
      !> The image: pixel (nm) and side L (nm).
      real(dp) :: pixel = 0, side = 0
   end type surface_spectrum

contains

   !> The isotropic PSD of heights z (nm, NP x NP, pixel d nm), the mean removed, the
   !> image taken as one period (a levelled scan's edges leak a little power). Bins: 8 per
   !> octave from q_L = 2 pi / L to q_d = pi / d.
   subroutine surface_spectrum_of(z, d, spectrum)
      real(dp), intent(in) :: z(:, :), d
      type(surface_spectrum), intent(out) :: spectrum
      complex(c_double_complex), allocatable :: a(:, :)
      real(dp), allocatable :: sums(:)
      integer, allocatable :: counts(:)
      integer :: n, i, j, ki, kj, b, bins
      real(dp) :: dq, qq, q_l, q_d, power
      n = size(z, 1)
      spectrum%pixel = d
      spectrum%side = n*d
      dq = 2*PI/spectrum%side
      q_l = dq
      q_d = PI/d
      allocate(a(n, n))
      a = cmplx(z - sum(z)/size(z), 0, kind=c_double_complex)
      call forward_complex_transform(a)
      bins = max(1, ceiling(8*log(q_d/q_l)/log(2.0_dp)))
      allocate(sums(bins), counts(bins))
      sums = 0
      counts = 0
      spectrum%slope_variance = 0
      do j = 1, n
         kj = j - 1
         if (kj > n/2) kj = kj - n
         do i = 1, n
            ki = i - 1
            if (ki > n/2) ki = ki - n
            if (ki == 0 .and. kj == 0) cycle
            qq = dq*sqrt(real(ki, dp)**2 + real(kj, dp)**2)
            if (qq > q_d*(1 + 1e-12_dp)) cycle
            ! C(q_k) = |A_k|^2 L^2 / (N^4 (2 pi)^2): sum_k C dq^2 is the mean square height.
            power = abs(a(i, j))**2*spectrum%side**2/(real(n, dp)**4*(2*PI)**2)
            spectrum%slope_variance = spectrum%slope_variance + qq**2*power*dq**2
            b = min(bins, 1 + int(8*log(qq/q_l)/log(2.0_dp)))
            sums(b) = sums(b) + power
            counts(b) = counts(b) + 1
         end do
      end do
      spectrum%q = pack([(q_l*2.0_dp**((b - 0.5_dp)/8), b = 1, bins)], counts > 0)
      spectrum%c = pack(sums/max(1, counts), counts > 0)
      spectrum%modes = pack(counts, counts > 0)
   end subroutine surface_spectrum_of

   !> The power law over the range it is measured on (least squares of log C on log q, each
   !> bin weighted by its Fourier modes): from 4 q_L (four wavelengths in the
   !> image: the longest waves are too few to average) to q_d / 2 (half the pixel's
   !> wavenumber: nearer the pixel the sampling distorts the spectrum). Refused (bad
   !> input) when the range spans less than MIN_FIT_RATIO, or log C is not a line in log q
   !> (r^2 < MIN_R_SQUARED), or the Hurst exponent is outside (0, 1): no scaling range.
   subroutine fit_spectrum(spectrum, status)
      type(surface_spectrum), intent(inout) :: spectrum
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: x(:), y(:), w(:)
      logical, allocatable :: keep(:)
      real(dp) :: mx, my, slope, sxx, syy, sxy
      spectrum%q_low = 4*2*PI/spectrum%side
      spectrum%q_high = PI/spectrum%pixel/2
      keep = spectrum%q >= spectrum%q_low .and. spectrum%q <= spectrum%q_high .and. spectrum%c > 0
      spectrum%points = count(keep)
      if (spectrum%q_high/spectrum%q_low < MIN_FIT_RATIO .or. spectrum%points < 4) then
         call set_error(status, STATUS_BAD_INPUT, "no scaling range: the PSD fit needs wavenumbers from 4 q_L to "// &
            "q_d/2 spanning a ratio of "//sig_str(MIN_FIT_RATIO, 2)//", found "// &
            sig_str(spectrum%q_high/spectrum%q_low, 3)//" (the ratio is NP/16: NP >= "// &
            int_str(nint(16*MIN_FIT_RATIO))//" pixels a side, found "//int_str(nint(spectrum%side/spectrum%pixel))//")")
         return
      end if
      ! Least squares in log-log, each bin weighted by its modes.
      x = log(pack(spectrum%q, keep))
      y = log(pack(spectrum%c, keep))
      w = real(pack(spectrum%modes, keep), dp)
      mx = sum(w*x)/sum(w)
      my = sum(w*y)/sum(w)
      sxx = sum(w*(x - mx)**2)
      syy = sum(w*(y - my)**2)
      sxy = sum(w*(x - mx)*(y - my))
      slope = sxy/sxx
      spectrum%r_squared = 0
      if (syy > 0) spectrum%r_squared = sxy**2/(sxx*syy)
      spectrum%hurst = -slope/2 - 1
      spectrum%prefactor = exp(my - slope*mx)
      if (spectrum%r_squared < MIN_R_SQUARED .or. .not. (spectrum%hurst > 0 .and. spectrum%hurst < 1)) then
         call set_error(status, STATUS_BAD_INPUT, "no scaling range: the PSD from "// &
            sig_str(spectrum%q_low, 3)//" to "//sig_str(spectrum%q_high, 3)//" 1/nm is not a self-affine power law "// &
            "(Hurst "//sig_str(spectrum%hurst, 3)//", r^2 "//sig_str(spectrum%r_squared, 3)//"; needed: 0 < H < 1, "// &
            "r^2 >= "//sig_str(MIN_R_SQUARED, 2)//")")
      end if
   end subroutine fit_spectrum

   !> m2 between q1 and q2 (1/nm) by the fitted power law: 2 pi int q^3 C0 q^-(2+2H) dq.
   pure real(dp) function subpixel_slope_variance(spectrum, q1, q2) result(m2)
      type(surface_spectrum), intent(in) :: spectrum
      real(dp), intent(in) :: q1, q2
      real(dp) :: e
      e = 2 - 2*spectrum%hurst
      m2 = 2*PI*spectrum%prefactor*(q2**e - q1**e)/e
   end function subpixel_slope_variance

   !> The refined area fraction of the grid: sum over the contact pixels of
   !> erf(sqrt(2) p_i / (E* sqrt(m2))) over NP^2 (m2 = 0: the contact pixels' count).
   pure real(dp) function refined_fraction(pressure, estar, m2, kappa) result(fraction)
      real(dp), intent(in) :: pressure(:, :), estar, m2
      !> The factor of p / (E* sqrt(m2)) in the erf: sqrt(2) in Persson's theory.
      real(dp), intent(in) :: kappa
      integer :: i, j
      fraction = 0
      do j = 1, size(pressure, 2)
         do i = 1, size(pressure, 1)
            if (pressure(i, j) <= 0) cycle
            if (m2 <= 0) then
               fraction = fraction + 1
            else
               fraction = fraction + erf(kappa*pressure(i, j)/(estar*sqrt(m2)))
            end if
         end do
      end do
      fraction = fraction/size(pressure)
   end function refined_fraction

   !> The factor kappa that carries the pressures of the solves at 2d to the area fractions
   !> of the solves at d over the band between them (m2 of the band): the root of
   !>    sum_k [ mean_i erf(kappa p_ki / (E* sqrt(m2))) - target_k ] = 0
   !> over the loads k together (the larger loads, with more contact pixels, weigh most),
   !> by bisection in log kappa. The refinement's one constant, measured on the scales the
   !> image resolves; 1e4 (no refinement) when the area did not fall from 2d to d.
   pure real(dp) function calibrate_kappa(pressure, estar, m2, target) result(kappa)
      real(dp), intent(in) :: pressure(:, :, :), estar, m2, target(:)
      real(dp) :: lo, hi
      integer :: it
      lo = log(1.0e-4_dp)
      hi = log(1.0e4_dp)
      kappa = exp(hi)
      if (mismatch(kappa) <= 0) return
      do it = 1, 200
         kappa = exp((lo + hi)/2)
         if (mismatch(kappa) < 0) then
            lo = log(kappa)
         else
            hi = log(kappa)
         end if
         if (hi - lo < 1.0e-12_dp) exit
      end do
      kappa = exp((lo + hi)/2)
   contains
      pure real(dp) function mismatch(k)
         real(dp), intent(in) :: k
         integer :: m
         mismatch = -sum(target)
         do m = 1, size(pressure, 3)
            mismatch = mismatch + refined_fraction(pressure(:, :, m), estar, m2, k)
         end do
      end function mismatch
   end function calibrate_kappa

   !> How the refinement's constant falls with the octaves of its band, measured on the
   !> image: alpha = log2((kappa_1 - sqrt 2) / (kappa_2 - sqrt 2)) from the constant over one
   !> octave (kappa_1: the solve at 2d carried to the area at d) and over two (kappa_2: 4d
   !> to d). 0 (no fall) when kappa_2 is not between sqrt 2 and kappa_1.
   pure real(dp) function kappa_decay(kappa_1, kappa_2) result(alpha)
      real(dp), intent(in) :: kappa_1, kappa_2
      alpha = 0
      if (kappa_2 > sqrt(2.0_dp) .and. kappa_2 < kappa_1) &
         alpha = log((kappa_1 - sqrt(2.0_dp))/(kappa_2 - sqrt(2.0_dp)))/log(2.0_dp)
   end function kappa_decay

   !> How the one-octave constant changes an octave finer, measured on the image: the ratio
   !> (kappa_1 - sqrt 2) / (kappa_c - sqrt 2) of the octave 2d -> d to the octave 4d -> 2d
   !> (kappa_c). 1 (no change) when either is not above sqrt 2.
   pure real(dp) function kappa_drift(kappa_1, kappa_c) result(drift)
      real(dp), intent(in) :: kappa_1, kappa_c
      drift = 1
      if (kappa_1 > sqrt(2.0_dp) .and. kappa_c > sqrt(2.0_dp)) drift = (kappa_1 - sqrt(2.0_dp))/(kappa_c - sqrt(2.0_dp))
   end function kappa_drift

   !> The refinement's constant for the band of N = log2(zeta) octaves below the pixel: its
   !> excess over Persson's sqrt 2 falls as a power of the band's octaves and changes by
   !> `drift` for each octave the band lies finer than the octave 2d -> d it was measured on
   !> (doc/studies.md):
   !>     kappa(N) = sqrt 2 + (kappa_1 - sqrt 2) max(N, 1)^-alpha drift^N.
   !> kappa_1 when kappa_1 is not above sqrt 2.
   elemental real(dp) function band_kappa(kappa_1, alpha, drift, zeta) result(kappa)
      real(dp), intent(in) :: kappa_1, alpha, drift, zeta
      real(dp) :: octaves
      kappa = kappa_1
      if (.not. (kappa_1 > sqrt(2.0_dp) .and. zeta > 1)) return
      octaves = log(zeta)/log(2.0_dp)
      kappa = sqrt(2.0_dp) + (kappa_1 - sqrt(2.0_dp))*max(octaves, 1.0_dp)**(-alpha)*drift**octaves
   end function band_kappa

   !> An edge of the refinement's uncertainty band (doc/studies.md, step 5). The band's
   !> constant kappa_band comes from the one-octave kappa_1 by an extrapolation that moved
   !> the excess over sqrt 2 by the factor f = (kappa_band - sqrt 2) / (kappa_1 - sqrt 2);
   !> its uncertainty is taken as that step once more, either way: excesses from
   !> (kappa_band - sqrt 2) min(f, 1/f) to (kappa_band - sqrt 2) max(f, 1/f), the upper edge
   !> (`upper` true) being kappa_1 itself when the excess falls. When the octaves measured
   !> give no trend (`trend` false: no 4d level) or no excess to extrapolate (kappa_1 or
   !> kappa_band at or below sqrt 2), the band runs between sqrt 2 and kappa_1.
   elemental real(dp) function band_edge(kappa_1, kappa_band, trend, upper) result(kappa)
      real(dp), intent(in) :: kappa_1, kappa_band
      logical, intent(in) :: trend, upper
      real(dp) :: e1, eb, f
      e1 = kappa_1 - sqrt(2.0_dp)
      eb = kappa_band - sqrt(2.0_dp)
      if (trend .and. e1 > 0 .and. eb > 0) then
         f = eb/e1
         if (upper) then
            kappa = sqrt(2.0_dp) + eb*max(f, 1/f)
         else
            kappa = sqrt(2.0_dp) + eb*min(f, 1/f)
         end if
      else if (upper) then
         kappa = max(kappa_1, sqrt(2.0_dp))
      else
         kappa = min(kappa_1, sqrt(2.0_dp))
      end if
   end function band_edge

   !> Persson's area fraction at nominal pressure p0 (GPa) over roughness of mean square
   !> slope m2: erf(sqrt(2) p0 / (E* sqrt(m2))).
   elemental real(dp) function persson_fraction(p0, estar, m2) result(fraction)
      real(dp), intent(in) :: p0, estar, m2
      fraction = erf(sqrt(2.0_dp)*p0/(estar*sqrt(m2)))
   end function persson_fraction

   !> Richardson's area at pixel h from the areas at d, 2d, 4d (section 4.5, eq. 4.12):
   !> A(h) = A_inf + c h^p with p = log2((A4 - A2)/(A2 - A1)); NaN when the three do not
   !> converge monotonically.
   elemental real(dp) function richardson_area(a1, a2, a4, d, h) result(area)
      real(dp), intent(in) :: a1, a2, a4, d, h
      real(dp) :: p, cdp
      area = ieee_value(1.0_dp, ieee_quiet_nan)
      if (.not. ((a4 - a2)*(a2 - a1) > 0)) return
      p = log((a4 - a2)/(a2 - a1))/log(2.0_dp)
      if (.not. (p > 0)) return
      cdp = (a2 - a1)/(2**p - 1)
      area = a1 - cdp + cdp*(h/d)**p
   end function richardson_area

   !> Magnifications from 1 to zeta_max: powers of sqrt(2), then zeta_max itself.
   pure function magnifications(zeta_max) result(zeta)
      real(dp), intent(in) :: zeta_max
      real(dp), allocatable :: zeta(:)
      integer :: k, m
      m = max(0, floor(2*log(zeta_max)/log(2.0_dp) + 1e-9_dp))
      zeta = [(sqrt(2.0_dp)**k, k = 0, m)]
      if (zeta(size(zeta)) < zeta_max*(1 - 1e-9_dp)) zeta = [zeta, zeta_max]
   end function magnifications
end module femcod_refine
