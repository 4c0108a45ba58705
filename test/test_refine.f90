!> The thesis' third model (studies/femcod_refine, femcod refine) on one small case whose
!> full-resolution answer the test computes: a self-affine surface (Hurst 0.7) solved at
!> 256^2 on a periodic cell, and the same surface averaged to 64^2 (4 x 4 block means,
!> taken here), solved and refined down to the 256^2 pixel.
module test_refine
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_surfaces, only: self_affine_surface
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, SOLVER_CG, BOUNDARY_PERIODIC
   use femcod_solver, only: solve_contact
   use femcod_refine, only: surface_spectrum, surface_spectrum_of, fit_spectrum, subpixel_slope_variance, kappa_decay, &
      kappa_drift, band_kappa, band_edge
   use femcod_refine_study, only: refine_answer, refine_contact
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_refine

   real(dp), parameter :: PI = acos(-1.0_dp)
   integer, parameter :: FINE = 256, FACTOR = 4
   real(dp), parameter :: PIXEL = 2
   !> Contact fractions about 1, 3 and 10 %: the loads are f E* h'rms / 2 over the cell
   !> (the fraction's linear law, Persson 2001 / Hyun et al. 2004, for the order only).
   real(dp), parameter :: FRACTIONS(3) = [0.01_dp, 0.03_dp, 0.1_dp]

contains

   subroutine collect_refine(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("the PSD fit finds the generator's Hurst exponent, 0.7", test_hurst), &
         new_unittest("refined 64^2 -> 256^2 pixel: far nearer the 256^2 solve than the 64^2 solve", test_refined), &
         new_unittest("Persson's theory: the code's column against the formula with the slopes taken here", &
            test_persson), &
         new_unittest("a surface with no scaling range is refused", test_no_scaling), &
         new_unittest("the constant's power law in the octaves, against values worked by hand", test_octave_law), &
         new_unittest("the band's edges, against values worked by hand; the refined area inside them", test_band) &
         ]
   end subroutine collect_refine

   function problem_of(z, d) result(p)
      real(dp), intent(in) :: z(:, :), d
      type(contact_problem) :: p
      p%label = "refine test"
      p%np = size(z, 1)
      p%pixel = d
      p%maxcont = p%np**2
      p%young = [200.0_dp, 2.0e12_dp, 2.0e12_dp]
      p%poisson = 0.25_dp
      p%lower = z
      allocate(p%upper(p%np, p%np))
      p%upper = 0
   end function problem_of

   !> kappa(N) = sqrt 2 + (kappa_1 - sqrt 2) max(N, 1)^-alpha drift^N, alpha =
   !> log2((kappa_1 - sqrt 2) / (kappa_2 - sqrt 2)), drift = (kappa_1 - sqrt 2) /
   !> (kappa_c - sqrt 2), worked by hand. Excesses of 1 over one octave and 1/2 over two:
   !> alpha = 1; without drift 1/4 over four octaves (zeta = 16) and 1/3 over three. Excesses
   !> 1 and 1/sqrt 2: alpha = 1/2, 1/2 over four octaves. A one-octave excess of 1 at 2d -> d
   !> and 5/4 at 4d -> 2d: drift 4/5, so with alpha = 1 four octaves give (1/4)(4/5)^4 =
   !> 64/625 and one octave 4/5; half an octave, (4/5)^(1/2). Without a measured fall or
   !> change (kappa_2 above kappa_1, either at or below sqrt 2), alpha = 0 and drift = 1.
   subroutine test_octave_law(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: R2 = sqrt(2.0_dp), TOL = 1e-13_dp
      call check(error, abs(kappa_decay(R2 + 1, R2 + 0.5_dp) - 1) < TOL, "alpha of excesses 1 and 1/2")
      if (allocated(error)) return
      call check(error, abs(band_kappa(R2 + 1, 1.0_dp, 1.0_dp, 16.0_dp) - (R2 + 0.25_dp)) < TOL, "four octaves, alpha 1")
      if (allocated(error)) return
      call check(error, abs(band_kappa(R2 + 1, 1.0_dp, 1.0_dp, 8.0_dp) - (R2 + 1/3.0_dp)) < TOL, "three octaves, alpha 1")
      if (allocated(error)) return
      call check(error, abs(kappa_decay(R2 + 1, R2 + 1/R2) - 0.5_dp) < TOL, "alpha of excesses 1 and 1/sqrt 2")
      if (allocated(error)) return
      call check(error, abs(band_kappa(R2 + 1, 0.5_dp, 1.0_dp, 16.0_dp) - (R2 + 0.5_dp)) < TOL, "four octaves, alpha 1/2")
      if (allocated(error)) return
      call check(error, abs(kappa_drift(R2 + 1, R2 + 1.25_dp) - 0.8_dp) < TOL, "drift of excesses 1 and 5/4")
      if (allocated(error)) return
      call check(error, abs(band_kappa(R2 + 1, 1.0_dp, 0.8_dp, 16.0_dp) - (R2 + 64/625.0_dp)) < TOL, &
         "four octaves, alpha 1, drift 4/5")
      if (allocated(error)) return
      call check(error, abs(band_kappa(R2 + 1, 1.0_dp, 0.8_dp, 2.0_dp) - (R2 + 0.8_dp)) < TOL .and. &
         abs(band_kappa(R2 + 1, 1.0_dp, 0.8_dp, sqrt(2.0_dp)) - (R2 + sqrt(0.8_dp))) < TOL, &
         "one octave and half an octave, drift 4/5")
      if (allocated(error)) return
      call check(error, kappa_decay(2.7_dp, 2.9_dp) == 0 .and. kappa_decay(2.7_dp, R2) == 0 .and. &
         kappa_decay(2.7_dp, 1.0_dp) == 0 .and. kappa_drift(2.7_dp, 1.0_dp) == 1 .and. kappa_drift(1.2_dp, 2.7_dp) == 1, &
         "nothing measured: alpha 0, drift 1")
      if (allocated(error)) return
      call check(error, band_kappa(2.7_dp, 0.0_dp, 1.0_dp, 16.0_dp) == 2.7_dp .and. &
         band_kappa(1.2_dp, 1.0_dp, 0.8_dp, 16.0_dp) == 1.2_dp .and. band_kappa(2.7_dp, 1.0_dp, 0.8_dp, 1.0_dp) == 2.7_dp, &
         "alpha 0 and drift 1, kappa_1 below sqrt 2, or no band: kappa_1")
   end subroutine test_octave_law

   !> The band's edges (band_edge) by hand: a one-octave excess of 1 carried to 1/2 (f =
   !> 1/2) gives excesses from 1/4 to 1 (kappa_1 itself); carried up to 2 (f = 2), from 1 to
   !> 4; carried to itself, no width. Without a trend the band runs from sqrt 2 to kappa_1,
   !> either way round. And on the refine study of test_refined's surface, every refined
   !> area lies between the band's (the area rises with kappa: erf is increasing).
   subroutine test_band(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: R2 = sqrt(2.0_dp), TOL = 1e-13_dp
      real(dp) :: z(FINE, FINE)
      type(refine_answer) :: answer
      type(status_type) :: st
      call check(error, abs(band_edge(R2 + 1, R2 + 0.5_dp, .true., .false.) - (R2 + 0.25_dp)) < TOL .and. &
         abs(band_edge(R2 + 1, R2 + 0.5_dp, .true., .true.) - (R2 + 1)) < TOL, "falling excess: 1/4 to 1")
      if (allocated(error)) return
      call check(error, abs(band_edge(R2 + 1, R2 + 2, .true., .false.) - (R2 + 1)) < TOL .and. &
         abs(band_edge(R2 + 1, R2 + 2, .true., .true.) - (R2 + 4)) < TOL, "rising excess: 1 to 4")
      if (allocated(error)) return
      call check(error, band_edge(R2 + 1, R2 + 1, .true., .false.) == R2 + 1 .and. &
         band_edge(R2 + 1, R2 + 1, .true., .true.) == R2 + 1, "no extrapolation: no width")
      if (allocated(error)) return
      call check(error, band_edge(2.7_dp, 2.7_dp, .false., .false.) == R2 .and. &
         band_edge(2.7_dp, 2.7_dp, .false., .true.) == 2.7_dp .and. band_edge(1.2_dp, 1.2_dp, .false., .false.) == 1.2_dp &
         .and. band_edge(1.2_dp, 1.2_dp, .false., .true.) == R2, "no trend: sqrt 2 to kappa_1")
      if (allocated(error)) return
      call self_affine_surface(FINE, PIXEL, 0.7_dp, 3.0_dp, 1, z)
      call refine_contact(problem_of(averaged(z), PIXEL*FACTOR), options_at(loads_for(z, PIXEL)), PIXEL, answer, st)
      call check(error, st%code == 0, st%message)
      if (allocated(error)) return
      call check(error, all(answer%band_low <= answer%band .and. answer%band <= answer%band_high), &
         "the band's constants bracket the refinement's")
      if (allocated(error)) return
      call check(error, all(answer%refined_low <= answer%refined .and. answer%refined <= answer%refined_high), &
         "the refined areas inside the band")
      if (allocated(error)) return
      call check(error, any(answer%refined_low < answer%refined .and. answer%refined < answer%refined_high), &
         "a band of some width below the pixel")
   end subroutine test_band

   !> 4 x 4 block means, written here.
   function averaged(z) result(w)
      real(dp), intent(in) :: z(:, :)
      real(dp), allocatable :: w(:, :)
      integer :: i, j, n
      n = size(z, 1)/FACTOR
      allocate(w(n, n))
      do j = 1, n
         do i = 1, n
            w(i, j) = sum(z((i - 1)*FACTOR + 1:i*FACTOR, (j - 1)*FACTOR + 1:j*FACTOR))/FACTOR**2
         end do
      end do
   end function averaged

   function options_at(loads) result(o)
      real(dp), intent(in) :: loads(:)
      type(contact_options) :: o
      o%solver = SOLVER_CG
      o%boundary = BOUNDARY_PERIODIC
      o%loads = loads
      allocate(o%approaches(0))
   end function options_at

   !> The self-affine generator draws C(q) ~ q^-(2+2H) (femcod_surfaces): over the fit range
   !> of a 256^2 image the fit gives H back within 0.05.
   subroutine test_hurst(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(FINE, FINE)
      type(surface_spectrum) :: s
      type(status_type) :: st
      call self_affine_surface(FINE, PIXEL, 0.7_dp, 3.0_dp, 1, z)
      call surface_spectrum_of(z, PIXEL, s)
      call fit_spectrum(s, st)
      call check(error, st%code == 0 .and. abs(s%hurst - 0.7_dp) < 0.05_dp .and. s%r_squared > 0.95_dp, &
         "H = "//to_string(s%hurst)//", r^2 = "//to_string(s%r_squared)//" "//st%message)
   end subroutine test_hurst

   !> Loads for FRACTIONS of contact on the surface z (pixel d): the rms slope by central
   !> differences on the periodic cell.
   function loads_for(z, d) result(loads)
      real(dp), intent(in) :: z(:, :), d
      real(dp) :: loads(size(FRACTIONS)), slope2
      slope2 = sum(((cshift(z, 1, 1) - cshift(z, -1, 1))/(2*d))**2 + ((cshift(z, 1, 2) - cshift(z, -1, 2))/(2*d))**2) &
         /size(z)
      loads = FRACTIONS*200/(1 - 0.25_dp**2)*sqrt(slope2)/2*(size(z, 1)*d)**2
   end function loads_for

   !> The area fractions of the 256^2 solve are the truth. At every load the 64^2 solve is
   !> off by more than 30 % (a pixel 4 times wider hides the roughness below it); the
   !> refinement down to 2 nm must have less than half the coarse solve's error.
   subroutine test_refined(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(FINE, FINE), truth(size(FRACTIONS)), LOADS(size(FRACTIONS))
      type(contact_result) :: res
      type(refine_answer) :: answer
      type(status_type) :: st
      integer :: k, last
      real(dp) :: coarse_error, refined_error
      type(contact_problem) :: scene
      call self_affine_surface(FINE, PIXEL, 0.7_dp, 3.0_dp, 1, z)
      LOADS = loads_for(z, PIXEL)
      scene = problem_of(z, PIXEL)
      call solve_contact(scene, options_at(LOADS), res, st)
      call check(error, st%code == 0, st%message)
      if (allocated(error)) return
      do k = 1, size(LOADS)
         truth(k) = real(res%states(k)%contacts, dp)/FINE**2
      end do
      call refine_contact(problem_of(averaged(z), PIXEL*FACTOR), options_at(LOADS), PIXEL, answer, st)
      call check(error, st%code == 0, st%message)
      if (allocated(error)) return
      last = size(answer%zeta)
      call check(error, abs(answer%zeta(last) - FACTOR) < 1e-9_dp, "refined down to the fine pixel")
      if (allocated(error)) return
      do k = 1, size(LOADS)
         coarse_error = abs(answer%coarse(1, k)/truth(k) - 1)
         refined_error = abs(answer%refined(last, k)/truth(k) - 1)
         call check(error, coarse_error > 0.3_dp .and. refined_error < coarse_error/2, "load "//to_string(LOADS(k))// &
            ": truth "//to_string(truth(k))//", coarse "//to_string(answer%coarse(1, k))//", refined "// &
            to_string(answer%refined(last, k)))
         if (allocated(error)) return
      end do
   end subroutine test_refined

   !> Persson (J. Chem. Phys. 115 (2001) 3840): A/A0 = erf(sqrt(2) p0 / (E* sqrt(m2))),
   !> m2 the mean square slope of the roughness. Here m2 of the image is taken by a direct
   !> discrete Fourier transform, summed over the disc |q| <= pi/d, plus the fitted power
   !> law's band to the fine pixel (from the code's fit, checked by test_hurst); the code's
   !> Persson column must agree to 1e-9.
   subroutine test_persson(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(FINE, FINE)
      real(dp), allocatable :: c(:, :)
      type(refine_answer) :: answer
      type(status_type) :: st
      real(dp) :: m2, d, estar, p0, q_d, expected, LOADS(size(FRACTIONS))
      integer :: k, last
      call self_affine_surface(FINE, PIXEL, 0.7_dp, 3.0_dp, 1, z)
      LOADS = loads_for(z, PIXEL)
      c = averaged(z)
      d = PIXEL*FACTOR
      call refine_contact(problem_of(c, d), options_at(LOADS), PIXEL, answer, st)
      call check(error, st%code == 0, st%message)
      if (allocated(error)) return
      m2 = disc_slope_variance(c - sum(c)/size(c), d)
      call check(error, abs(m2/answer%spectrum%slope_variance - 1) < 1e-9_dp, "m2 of the image: "// &
         to_string(m2)//" here, "//to_string(answer%spectrum%slope_variance)//" in the code")
      if (allocated(error)) return
      estar = 200/(1 - 0.25_dp**2)
      q_d = PI/d
      last = size(answer%zeta)
      m2 = m2 + subpixel_slope_variance(answer%spectrum, q_d, FACTOR*q_d)
      do k = 1, size(LOADS)
         p0 = LOADS(k)/(size(c, 1)*d)**2
         expected = erf(sqrt(2.0_dp)*p0/(estar*sqrt(m2)))
         call check(error, abs(answer%persson(last, k)/expected - 1) < 1e-9_dp, "Persson at "//to_string(LOADS(k))// &
            ": "//to_string(answer%persson(last, k))//", expected "//to_string(expected))
         if (allocated(error)) return
      end do
   end subroutine test_persson

   !> sum over |q| <= pi/d of |q|^2 |H(q)|^2 / N^4, H the DFT of z, written out (O(N^4)).
   function disc_slope_variance(z, d) result(m2)
      real(dp), intent(in) :: z(:, :), d
      real(dp) :: m2
      complex(dp) :: h, wi(size(z, 1)), wj(size(z, 1))
      integer :: n, ki, kj, i, j
      real(dp) :: q2, dq
      n = size(z, 1)
      dq = 2*PI/(n*d)
      m2 = 0
      do kj = -n/2 + 1, n/2
         do ki = -n/2 + 1, n/2
            q2 = dq**2*(real(ki, dp)**2 + real(kj, dp)**2)
            if (q2 > (PI/d)**2*(1 + 1e-12_dp) .or. (ki == 0 .and. kj == 0)) cycle
            wi = [(exp(cmplx(0, -2*PI*ki*(i - 1)/real(n, dp), dp)), i = 1, n)]
            wj = [(exp(cmplx(0, -2*PI*kj*(j - 1)/real(n, dp), dp)), j = 1, n)]
            h = sum(matmul(wi, z)*wj)
            m2 = m2 + q2*abs(h)**2/real(n, dp)**4
         end do
      end do
   end function disc_slope_variance

   !> A single sinusoid has no power law: refused with "no scaling range".
   subroutine test_no_scaling(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(64, 64)
      type(refine_answer) :: answer
      type(status_type) :: st
      integer :: i, j
      do j = 1, 64
         do i = 1, 64
            z(i, j) = 2*cos(2*PI*i/16)*cos(2*PI*j/16)
         end do
      end do
      call refine_contact(problem_of(z, 1.0_dp), options_at([100.0_dp]), 0.5_dp, answer, st)
      call check(error, st%code == 3 .and. index(st%message, "no scaling range") > 0, st%message)
   end subroutine test_no_scaling
end module test_refine
