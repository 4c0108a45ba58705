!> The Love kernel of a periodic half-space (`--boundary periodic`): the square-pixel
!> influence of femcod_love summed over all periodic images of an NP x NP cell.
!>
!> The image sum of I diverges (I ~ 1/rho), but only in its mean: a periodic load with a
!> non-zero mean displaces a half-space without bound. femcod fixes the convention that
!> the displacement field has zero mean over the cell (the zero-frequency coefficient of
!> the kernel is 0), as the periodic FFT solvers of the literature do (Stanley and Kato
!> 1997; tamaas, ContactMechanics). The rigid-body approach then measures how far the
!> mean planes of the two surfaces came together: mean gap = mean g0 - approach.
!>
!> The kernel is computed in Fourier space, exactly. By Poisson's summation the DFT of the
!> periodised samples of I at the frequency (a, b) = (k1, k2)/NP (cycles per pixel) is
!> the alias sum of the continuous transform of (pixel box) * 1/r:
!>     S(a, b) = sum over integers m, n of s(a + m) s(b + n) / |(a + m, b + n)|,
!>     s(x) = sin(pi x)/(pi x),
!> which converges slowly. With 1/|v| = 2/sqrt(pi) int_0^inf exp(-t^2 |v|^2) dt the sum
!> separates:
!>     S(a, b) = 2/sqrt(pi) int_0^inf A(a, t) A(b, t) dt,
!>     A(a, t) = sum_m s(a + m) exp(-t^2 (a + m)^2)
!>             = erf(pi/(2t)) + sum_{k>=1} [erfc(pi(k - 1/2)/t) - erfc(pi(k + 1/2)/t)] cos(2 pi k a),
!> the second form by Poisson's summation again (used for t < 1, where the first
!> converges slowly; both need at most 8 terms). With t = exp(u) the integrand is
!> analytic in the strip |Im u| < pi/4 and decays doubly exponentially at both ends, so
!> the trapezoidal rule in u with step 1/8 is exact to about exp(-2 pi (pi/4) 8) = 1e-17
!> of the integral. The integral for all (NP/2 + 1)^2 pairs is then one symmetric
!> rank-k update (BLAS dsyrk): A (NP/2 + 1 x about 400 nodes) times its transpose.
!> In the continuum limit S -> 1/|(a, b)|: the displacement over the pressure is
!> 2/(E* |q|), as for the continuous periodic half-space.
module femcod_love_periodic
   use femcod_kinds, only: dp
   use femcod_lapack, only: dsyrk, dgemm
   use femcod_convolution, only: inverse_half_spectrum
   implicit none
   private
   public :: periodic_love_spectrum, periodic_love_spectrum_rows, periodic_offset_table, periodic_cerruti_spectra

   real(dp), parameter :: pi = 3.141592653589793238462643383279502884_dp
   !> The trapezoidal rule's step in u = ln t (module header).
   real(dp), parameter :: NODE_STEP = 0.125_dp

contains

   !> S(k1, k2), k1, k2 = 0 .. NP/2: the DFT of the periodic kernel at the frequencies
   !> (k1, k2)/NP (dimensionless, pixel units; the table's DFT, so that the periodic
   !> convolution of forces F is c * IDFT(S * DFT(F))). S is even in both frequencies
   !> and symmetric; S(0, 0) = 0 (zero-mean displacements).
   function periodic_love_spectrum(np) result(s)
      integer, intent(in) :: np
      real(dp) :: s(0:np/2, 0:np/2)
      real(dp), allocatable :: a(:, :)
      integer :: kh, k
      kh = np/2
      call sampled_factors(np, a)
      s = 0
      call dsyrk("U", "N", kh + 1, size(a, 2), 1.0_dp, a, kh + 1, 0.0_dp, s, kh + 1)
      do k = 0, kh
         s(k + 1:kh, k) = s(k, k + 1:kh)
      end do
      s(0, 0) = 0
   end function periodic_love_spectrum

   !> The rows k1 = first .. first + count - 1 of periodic_love_spectrum, S(k1, k2) for
   !> k2 = 0 .. NP/2 (the same sums, one matrix product), so that a process holding some
   !> frequencies (femcod-mpi's ranks) need not make the whole quarter spectrum.
   function periodic_love_spectrum_rows(np, first, count) result(s)
      integer, intent(in) :: np, first, count
      real(dp) :: s(first:first + count - 1, 0:np/2)
      real(dp), allocatable :: a(:, :)
      integer :: kh
      kh = np/2
      if (count <= 0) return
      call sampled_factors(np, a)
      call dgemm("N", "T", count, kh + 1, size(a, 2), 1.0_dp, a(first, 1), kh + 1, a, kh + 1, 0.0_dp, s, count)
      if (first == 0) s(0, 0) = 0
   end function periodic_love_spectrum_rows

   !> The factors of the spectrum's integral: a(k, j) = sqrt(trapezoidal weight at node
   !> j) A(k/NP, t_j), k = 0 .. NP/2, so that S = a a^T (module header).
   subroutine sampled_factors(np, a)
      integer, intent(in) :: np
      real(dp), allocatable, intent(out) :: a(:, :)
      real(dp), allocatable :: nodes(:)
      real(dp) :: t, w
      integer :: kh, j, k
      kh = np/2
      nodes = integration_nodes(np)
      allocate(a(0:kh, size(nodes)))
      !$omp parallel do private(t, w, k)
      do j = 1, size(nodes)
         t = nodes(j)
         ! Trapezoidal weight (dt = t du), its square root shared by the two factors.
         w = sqrt(2/sqrt(pi)*NODE_STEP*t)
         do k = 0, kh
            a(k, j) = w*sampled_box_gaussian(real(k, dp)/real(np, dp), t)
         end do
      end do
      !$omp end parallel do
   end subroutine sampled_factors

   !> The nodes t_j = exp(u_j) of the trapezoidal rule in u = ln t, step NODE_STEP, for a
   !> cell of NP pixels. The ends: below t = 1e-17 S's integrand is 2/sqrt(pi) (A = 1 +
   !> O(t^2)), so the part left out is 1e-17 (the Cerruti moments' is 0 there); above
   !> t = 7 NP every factor exp(-t^2 |v|^2) with |v| >= 1/NP is below exp(-49).
   pure function integration_nodes(np) result(nodes)
      integer, intent(in) :: np
      real(dp), allocatable :: nodes(:)
      real(dp) :: u_low, u_high
      integer :: j
      u_low = log(1.0e-17_dp)
      u_high = log(7.0_dp*max(np, 1))
      nodes = [(exp(u_low + (j - 1)*NODE_STEP), j = 1, ceiling((u_high - u_low)/NODE_STEP) + 1)]
   end function integration_nodes

   !> The periodic Cerruti integrals' spectra (femcod_cerruti): with the transforms
   !>     int int X^2/rho^3 -> fy^2/|f|^3,   int int X Y/rho^3 -> -fx fy/|f|^3
   !> (f in cycles per pixel; their sum with Y^2/rho^3 is Love's 1/|f|) and 1/|v|^3 =
   !> 4/sqrt(pi) int_0^inf t^2 exp(-t^2 |v|^2) dt, the alias sums separate as S's do:
   !>     xx(kx, ky) = sum s(ax + m) s(ay + n) (ay + n)^2/|v|^3 = 4/sqrt(pi) int t^2 A(ax) B(ay) dt,
   !>     c(kx, ky)  = sum s s (ax + m) (ay + n)/|v|^3         = 4/sqrt(pi) int t^2 C(ax) C(ay) dt,
   !> ax = kx/NP, ay = ky/NP, kx, ky = 0 .. NP/2, with B(a, t) = sum_m s(a + m) (a + m)^2
   !> exp(-t^2 (a + m)^2) and C the same with (a + m) (sampled_box_moments). The same
   !> trapezoidal rule in u = ln t as S (its integrand t^3 A B decays as exp(-pi^2/(4 t^2))
   !> at small t); xx is not symmetric: the Y^2 integral's spectrum is its transpose. A
   !> and B are even in a, C odd; all three 0 at zero frequency (zero-mean displacements).
   subroutine periodic_cerruti_spectra(np, xx, c)
      integer, intent(in) :: np
      real(dp), intent(out) :: xx(0:np/2, 0:np/2), c(0:np/2, 0:np/2)
      real(dp), allocatable :: a(:, :), b(:, :), cc(:, :), ts(:)
      real(dp) :: t, w
      integer :: kh, nodes, j, k
      kh = np/2
      ts = integration_nodes(np)
      nodes = size(ts)
      allocate(a(0:kh, nodes), b(0:kh, nodes), cc(0:kh, nodes))
      !$omp parallel do private(t, w, k)
      do j = 1, nodes
         t = ts(j)
         w = sqrt(4/sqrt(pi)*NODE_STEP*t**3)
         do k = 0, kh
            a(k, j) = w*sampled_box_gaussian(real(k, dp)/real(np, dp), t)
            call sampled_box_moments(real(k, dp)/real(np, dp), t, b(k, j), cc(k, j))
            b(k, j) = w*b(k, j)
            cc(k, j) = w*cc(k, j)
         end do
      end do
      !$omp end parallel do
      call dgemm("N", "T", kh + 1, kh + 1, nodes, 1.0_dp, a, kh + 1, b, kh + 1, 0.0_dp, xx, kh + 1)
      call dgemm("N", "T", kh + 1, kh + 1, nodes, 1.0_dp, cc, kh + 1, cc, kh + 1, 0.0_dp, c, kh + 1)
      xx(0, 0) = 0
      c(0, 0) = 0
   end subroutine periodic_cerruti_spectra

   !> B(a, t) = sum_m s(a + m) (a + m)^2 exp(-t^2 (a + m)^2) and C(a, t) = sum_m s(a + m)
   !> (a + m) exp(-t^2 (a + m)^2), 0 <= a <= 1/2: directly for t >= 1 (s(a + m) (a + m) =
   !> (-1)^m sin(pi a)/pi), else by Poisson's summation, with g(x) = exp(-pi^2 x^2/t^2):
   !>     B = sqrt(pi)/(2 t^3) [g(1/2) - 2 sum_k>=1 ((k - 1/2) g(k - 1/2) - (k + 1/2) g(k + 1/2)) cos(2 pi k a)],
   !>     C = 1/(sqrt(pi) t) sum_k>=1 (g(k - 1/2) - g(k + 1/2)) sin(2 pi k a).
   !> Both are 0 at a = 0 (and C at a = 1/2).
   pure subroutine sampled_box_moments(a, t, b, c)
      real(dp), intent(in) :: a, t
      real(dp), intent(out) :: b, c
      real(dp) :: x, sa, e
      integer :: m, mmax, k
      b = 0
      c = 0
      ! Below t = 0.15 both are below exp(-pi^2/(4 t^2)) / t^3 < 1e-44 of their scale.
      if (a == 0 .or. t < 0.15_dp) return
      if (t >= 1) then
         sa = sin(pi*a)/pi
         mmax = ceiling(6.3_dp/t + 0.5_dp)
         do m = -mmax, mmax
            x = a + m
            e = merge(1, -1, mod(m, 2) == 0)*sa*exp(-(t*x)**2)
            b = b + e*x
            c = c + e
         end do
      else
         b = g(0.5_dp)
         do k = 1, ceiling(2*t + 0.5_dp) + 1
            b = b - 2*((k - 0.5_dp)*g(k - 0.5_dp) - (k + 0.5_dp)*g(k + 0.5_dp))*cos(2*pi*k*a)
            c = c + (g(k - 0.5_dp) - g(k + 0.5_dp))*sin(2*pi*k*a)
         end do
         b = sqrt(pi)/(2*t**3)*b
         c = c/(sqrt(pi)*t)
      end if
   contains
      pure real(dp) function g(y)
         real(dp), intent(in) :: y
         g = exp(-(pi*y/t)**2)
      end function g
   end subroutine sampled_box_moments

   !> A(a, t) = sum_m s(a + m) exp(-t^2 (a + m)^2), 0 <= a <= 1/2, t > 0: the samples
   !> at the pixel centres, shifted by a, of the pixel box smoothed by a Gaussian.
   pure real(dp) function sampled_box_gaussian(a, t) result(total)
      real(dp), intent(in) :: a, t
      real(dp) :: x, sa
      integer :: m, mmax, k
      if (t >= 1) then
         ! Direct: the Gaussian ends the sum, exp(-t^2 (|m| - 1/2)^2) < 1e-17 beyond.
         ! s(a + m) = (-1)^m sin(pi a)/(pi (a + m)), exact 0 for a = 0, m /= 0.
         sa = sin(pi*a)
         mmax = ceiling(6.3_dp/t + 0.5_dp)
         total = 0
         do m = -mmax, mmax
            x = a + m
            if (x == 0) then
               total = total + 1
            else
               total = total + merge(1, -1, mod(m, 2) == 0)*sa/(pi*x)*exp(-(t*x)**2)
            end if
         end do
      else
         ! Dual: the transform of the smoothed box, a difference of error functions
         ! that ends the sum, erfc(pi (k - 1/2)/t) < 1e-17 beyond k = 2t + 1/2.
         total = erf(pi/(2*t))
         do k = 1, ceiling(2*t + 0.5_dp) + 1
            total = total + (erfc(pi*(k - 0.5_dp)/t) - erfc(pi*(k + 0.5_dp)/t))*cos(2*pi*k*a)
         end do
      end if
   end function sampled_box_gaussian

   !> The periodic influence table K(p, q), p, q = 0 .. NP-1 (dimensionless, as
   !> femcod_love's offset_table): the inverse DFT of periodic_love_spectrum, even and
   !> periodic (K(p, q) = K(NP - p, q)), so that K(|i - k|, |j - l|) is the influence
   !> between any two pixels of the cell, images included; its mean over the cell is 0.
   function periodic_offset_table(np) result(table)
      integer, intent(in) :: np
      real(dp) :: table(0:np - 1, 0:np - 1)
      real(dp), allocatable :: s(:, :)
      complex(dp), allocatable :: spectrum(:, :)
      integer :: kh, k1, k2
      kh = np/2
      allocate(s(0:kh, 0:kh), spectrum(kh + 1, np))
      s(:, :) = periodic_love_spectrum(np)
      ! Column-major (kh + 1) x np half spectrum of a row-major np x np transform: the
      ! first index is the halved frequency k2, the second k1 = 0 .. np-1 (mirrored).
      do k1 = 0, np - 1
         do k2 = 0, kh
            spectrum(k2 + 1, k1 + 1) = cmplx(s(k2, min(k1, np - k1)), 0, dp)
         end do
      end do
      call inverse_half_spectrum(spectrum, table)
      table = table/real(np, dp)**2
   end function periodic_offset_table
end module femcod_love_periodic
