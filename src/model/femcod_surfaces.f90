!> Height maps (nm) on NP x NP grids of square pixels of side d (nm): the thesis'
!> verification shapes and rough surfaces, plus the transforms a user needs.
!> Pixel (i, j) is row i, column j; its centre lies at x = (j - c) d, y = (c - i) d
!> with c = (NP + 1)/2, so the grid centre is a pixel centre for odd NP and a pixel
!> corner for even NP. No I/O here.
module femcod_surfaces
   use, intrinsic :: iso_c_binding, only: c_double_complex
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_random, only: random_stream, seed_stream, normal, uniform, advance_stream
   use, intrinsic :: iso_fortran_env, only: int64
   use femcod_sort, only: merge_sort_index
   implicit none
   private
   public :: circle_punch, square_punch, sphere_cap, sinusoid_surface, weierstrass_mandelbrot, wm_terms
   public :: block_average
   public :: self_affine_surface, self_affine_spectrum, remove_plane, rms_height, downsample_subsample, &
      downsample_average, plane_tilt

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   !> Circular flat punch: the `round(area/d**2)` pixels nearest the centre pixel
   !> (NP must be odd) get height `height`, all others 0. Whole rings of equidistant
   !> pixels are taken while they fit; the last ring is split into whole orbits of
   !> the 90-degree rotation, taken in row-wise order of their first pixel, so the
   !> punch stays symmetric under that rotation. Returns the number of punch pixels.
   subroutine circle_punch(np, pixel, area, height, z, npunch, status)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, area, height
      real(dp), intent(out) :: z(np, np)
      integer, intent(out) :: npunch
      type(status_type), intent(inout) :: status
      integer :: target, c, i, j, k, n, ring_end, need, p, q, r2
      integer, allocatable :: order(:), di(:), dj(:)
      real(dp), allocatable :: dist2(:)
      logical, allocatable :: taken(:)
      z = 0
      npunch = 0
      if (mod(np, 2) /= 1) then
         call set_error(status, STATUS_BAD_INPUT, "circle punch: NP must be odd (the centre is a pixel centre)")
         return
      end if
      target = nint(area/pixel**2)
      if (target < 1 .or. target > np**2) then
         call set_error(status, STATUS_BAD_INPUT, "circle punch: the area must hold 1 to NP**2 pixels")
         return
      end if
      c = (np + 1)/2
      n = np*np
      allocate(dist2(n), di(n), dj(n), order(n), taken(n))
      k = 0
      do i = 1, np
         do j = 1, np
            k = k + 1
            di(k) = i - c
            dj(k) = j - c
            dist2(k) = real(di(k)**2 + dj(k)**2, dp)
         end do
      end do
      call merge_sort_index(dist2, order)
      taken = .false.
      k = 0
      do while (npunch < target)
         r2 = nint(dist2(order(k + 1)))
         ring_end = k
         do while (ring_end < n)
            if (nint(dist2(order(ring_end + 1))) /= r2) exit
            ring_end = ring_end + 1
         end do
         need = target - npunch
         if (ring_end - k <= need) then
            taken(order(k + 1:ring_end)) = .true.
            npunch = npunch + ring_end - k
         else
            if (mod(need, 4) /= 0) then
               call set_error(status, STATUS_BAD_INPUT, "circle punch: the last ring cannot be split "// &
                  "symmetrically under 90-degree rotation (choose another area)")
               return
            end if
            do i = k + 1, ring_end
               if (npunch == target) exit
               if (taken(order(i))) cycle
               p = di(order(i))
               q = dj(order(i))
               ! The orbit of (p, q) under rotation by 90 degrees: (p,q) (q,-p) (-p,-q) (-q,p).
               call take(p, q)
               call take(q, -p)
               call take(-p, -q)
               call take(-q, p)
               npunch = npunch + 4
            end do
         end if
         k = ring_end
      end do
      do k = 1, n
         if (taken(k)) z(di(k) + c, dj(k) + c) = height
      end do
   contains
      subroutine take(a, b)
         integer, intent(in) :: a, b
         taken((a + c - 1)*np + b + c) = .true.
      end subroutine take
   end subroutine circle_punch

   !> Square flat punch: the central `np/3` x `np/3` pixels (NP divisible by 3) get
   !> height `height`, all others 0 (a 10 nm punch in a 30 nm region, Fig. 4.12).
   subroutine square_punch(np, height, z, status)
      integer, intent(in) :: np
      real(dp), intent(in) :: height
      real(dp), intent(out) :: z(np, np)
      type(status_type), intent(inout) :: status
      integer :: m
      z = 0
      if (mod(np, 3) /= 0) then
         call set_error(status, STATUS_BAD_INPUT, "square punch: NP must be divisible by 3")
         return
      end if
      m = np/3
      z(m + 1:2*m, m + 1:2*m) = height
   end subroutine square_punch

   !> Rigid sphere of radius `radius` (nm) centred on the grid: z = sqrt(R**2 - r**2)
   !> inside r < R, 0 outside (Fig. 4.14).
   pure subroutine sphere_cap(np, pixel, radius, z)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, radius
      real(dp), intent(out) :: z(np, np)
      integer :: i, j
      real(dp) :: x, y, c, r2
      c = (np + 1)/2.0_dp
      do j = 1, np
         x = (j - c)*pixel
         do i = 1, np
            y = (c - i)*pixel
            r2 = x*x + y*y
            z(i, j) = 0
            if (r2 < radius**2) z(i, j) = sqrt(radius**2 - r2)
         end do
      end do
   end subroutine sphere_cap

   !> The sinusoid of eq. (3.3): z = A cos(x/w) cos(y/w) (A = 1 nm and w = 10 nm in the
   !> thesis, summit radius w**2/A = 100 nm), x and y from the grid centre.
   pure subroutine sinusoid_surface(np, pixel, amplitude, wavelength_scale, z)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, amplitude, wavelength_scale
      real(dp), intent(out) :: z(np, np)
      integer :: i, j
      real(dp) :: c
      c = (np + 1)/2.0_dp
      do j = 1, np
         do i = 1, np
            z(i, j) = amplitude*cos((j - c)*pixel/wavelength_scale)*cos((c - i)*pixel/wavelength_scale)
         end do
      end do
   end subroutine sinusoid_surface

   !> Number of cosine terms n = 0..nmax of eq. (3.7): nmax = int(log(Lmax/Lmin)/log(gamma)),
   !> so nmax + 1 terms (18 for gamma = 1.5 and 5 for gamma = 5 between 1 nm and 1 um).
   pure integer function wm_terms(lmax, lmin, gamma)
      real(dp), intent(in) :: lmax, lmin, gamma
      wm_terms = int(log(lmax/lmin)/log(gamma)) + 1
   end function wm_terms

   !> Weierstrass-Mandelbrot surface of eq. (3.6) (Ausloos-Berman, as used by Yan and
   !> Komvopoulos):
   !>   z = L (G/L)**(Ds-2) sqrt(ln(gamma)/M) sum_m sum_n gamma**((Ds-3) n)
   !>       [cos(phi_mn) - cos(2 pi gamma**n r/L cos(theta - pi m/M) + phi_mn)]
   !> with L = Lmax the sample size, n = 0..nmax from eq. (3.7), random phases phi.
   subroutine weierstrass_mandelbrot(np, pixel, ds, g, gamma, lmax, lmin, nridges, seed, z)
      integer, intent(in) :: np, nridges, seed
      real(dp), intent(in) :: pixel, ds, g, gamma, lmax, lmin
      real(dp), intent(out) :: z(np, np)
      type(random_stream) :: stream
      real(dp), allocatable :: phase(:, :)
      real(dp), allocatable :: amp(:), wave(:), cm(:), sm(:), row(:)
      real(dp) :: pref, x, y, c, base, u
      complex(dp) :: rot, step
      integer :: m, n, i, j, nterms
      nterms = wm_terms(lmax, lmin, gamma)
      allocate(phase(nridges, 0:nterms - 1))
      call seed_stream(stream, seed)
      do n = 0, nterms - 1
         do m = 1, nridges
            call uniform(stream, u)
            phase(m, n) = 2*pi*u
         end do
      end do
      pref = lmax*(g/lmax)**(ds - 2)*sqrt(log(gamma)/nridges)
      ! r cos(theta - pi m/M) = x cos(pi m/M) + y sin(pi m/M): one cosine per term and
      ! pixel; amplitudes, wave numbers and the constant part computed once.
      allocate(amp(0:nterms - 1), wave(0:nterms - 1), cm(nridges), sm(nridges))
      do n = 0, nterms - 1
         amp(n) = gamma**((ds - 3)*n)
         wave(n) = 2*pi*gamma**n/lmax
      end do
      do m = 1, nridges
         cm(m) = cos(pi*m/nridges)
         sm(m) = sin(pi*m/nridges)
      end do
      base = 0
      do m = 1, nridges
         do n = 0, nterms - 1
            base = base + amp(n)*cos(phase(m, n))
         end do
      end do
      c = (np + 1)/2.0_dp
      ! Along a row the phase grows by wave(n) cm(m) pixel per column: the cosines
      ! follow from one complex rotation per term, restarted exactly every 64 columns
      ! (rounding stays below 1e-14 of a term).
      allocate(row(np))
      !$omp parallel do private(i, y, m, n, j, x, rot, step, row)
      do i = 1, np
         y = (c - i)*pixel
         row = base
         do m = 1, nridges
            do n = 0, nterms - 1
               step = exp(cmplx(0.0_dp, wave(n)*cm(m)*pixel, dp))
               do j = 1, np
                  if (mod(j - 1, 64) == 0) then
                     x = (j - c)*pixel
                     rot = exp(cmplx(0.0_dp, wave(n)*(x*cm(m) + y*sm(m)) + phase(m, n), dp))
                  else
                     rot = rot*step
                  end if
                  row(j) = row(j) - amp(n)*real(rot, dp)
               end do
            end do
         end do
         z(i, :) = pref*row
      end do
   end subroutine weierstrass_mandelbrot

   !> Self-affine Gaussian random surface by Fourier filtering: power spectrum
   !> C(q) ~ q**(-2(1+H)) for 2 pi/L <= |q| <= pi/d (L = NP d), zero elsewhere,
   !> Gaussian random complex amplitudes (reproducible from `seed`), inverse FFT
   !> (FFTW), real part, mean removed, scaled to the rms height `rms` (nm). With `cutoff`
   !> (nm, above 2 d), no roughness below that wavelength: |q| <= 2 pi/cutoff, the same
   !> random amplitudes above it.
   subroutine self_affine_surface(np, pixel, hurst, rms, seed, z, cutoff)
      use femcod_convolution, only: inverse_complex_transform
      integer, intent(in) :: np, seed
      real(dp), intent(in) :: pixel, hurst, rms
      real(dp), intent(out) :: z(np, np)
      real(dp), intent(in), optional :: cutoff
      complex(c_double_complex), allocatable :: spec(:, :), field(:, :)
      allocate(spec(np, np), field(np, np))
      call self_affine_spectrum(np, pixel, hurst, seed, 0, np, spec, cutoff)
      ! FFTW is row-major: a Fortran (np, np) array is an (np, np) C array transposed,
      ! which a 2-D transform of a square grid does not mind.
      call inverse_complex_transform(spec, field)
      z = real(field, dp)
      z = z - sum(z)/size(z)
      if (rms_height(z) > 0) z = z*(rms/rms_height(z))
   end subroutine self_affine_surface

   !> Columns first_column + 1 .. first_column + columns of the self-affine surface's
   !> spectrum (self_affine_surface), into spec(np, columns): the random stream of `seed`
   !> jumped ahead to the first of them (four uniforms per frequency: two normal
   !> deviates), so that each of femcod-mpi's ranks draws its own columns and together
   !> they draw what one core draws. `cutoff` (nm): the shortest wavelength, when above 2 d.
   pure subroutine self_affine_spectrum(np, pixel, hurst, seed, first_column, columns, spec, cutoff)
      integer, intent(in) :: np, seed, first_column, columns
      real(dp), intent(in) :: pixel, hurst
      complex(c_double_complex), intent(out) :: spec(:, :)
      real(dp), intent(in), optional :: cutoff
      type(random_stream) :: stream
      real(dp) :: qx, qy, q, qmin, qmax, a, b, amp
      integer :: i, j, fi, fj
      call seed_stream(stream, seed)
      call advance_stream(stream, 4*int(np, int64)*first_column)
      qmin = 2*pi/(np*pixel)
      qmax = pi/pixel
      if (present(cutoff)) then
         if (cutoff > 2*pixel) qmax = 2*pi/cutoff
      end if
      do j = first_column + 1, first_column + columns
         fj = j - 1
         if (fj > np/2) fj = fj - np
         qx = 2*pi*fj/(np*pixel)
         do i = 1, np
            fi = i - 1
            if (fi > np/2) fi = fi - np
            qy = 2*pi*fi/(np*pixel)
            q = sqrt(qx*qx + qy*qy)
            call normal(stream, a)
            call normal(stream, b)
            amp = 0
            if (q >= qmin*(1 - 1.0e-12_dp) .and. q <= qmax*(1 + 1.0e-12_dp)) amp = q**(-(1 + hurst))
            spec(i, j - first_column) = cmplx(a*amp, b*amp, c_double_complex)
         end do
      end do
   end subroutine self_affine_spectrum

   !> Root-mean-square height about the mean (nm).
   pure real(dp) function rms_height(z)
      real(dp), intent(in) :: z(:, :)
      real(dp) :: mean
      mean = sum(z)/size(z)
      rms_height = sqrt(sum((z - mean)**2)/size(z))
   end function rms_height

   !> The least-squares plane z = mz + b (i - mi) + c (j - mj) of a grid of heights
   !> (mi, mj the centre indices): its mean and slopes per pixel (nm, nm/pixel).
   pure subroutine plane_fit(z, mz, b, c)
      real(dp), intent(in) :: z(:, :)
      real(dp), intent(out) :: mz, b, c
      real(dp) :: mi, mj, sii, sjj, szi, szj
      integer :: i, j
      mi = (size(z, 1) + 1)/2.0_dp
      mj = (size(z, 2) + 1)/2.0_dp
      mz = sum(z)/size(z)
      sii = 0; sjj = 0; szi = 0; szj = 0
      do j = 1, size(z, 2)
         do i = 1, size(z, 1)
            sii = sii + (i - mi)**2
            sjj = sjj + (j - mj)**2
            szi = szi + (z(i, j) - mz)*(i - mi)
            szj = szj + (z(i, j) - mz)*(j - mj)
         end do
      end do
      ! On a full rectangular grid the i and j deviations are orthogonal.
      b = 0
      c = 0
      if (sii > 0) b = szi/sii
      if (sjj > 0) c = szj/sjj
   end subroutine plane_fit

   !> Subtract the least-squares plane z = a + b i + c j (tilt and offset removal).
   pure subroutine remove_plane(z)
      real(dp), intent(inout) :: z(:, :)
      real(dp) :: mi, mj, mz, b, c
      integer :: i, j
      call plane_fit(z, mz, b, c)
      mi = (size(z, 1) + 1)/2.0_dp
      mj = (size(z, 2) + 1)/2.0_dp
      do j = 1, size(z, 2)
         do i = 1, size(z, 1)
            z(i, j) = z(i, j) - mz - b*(i - mi) - c*(j - mj)
         end do
      end do
   end subroutine remove_plane

   !> The least-squares plane's rise across the grid (nm: its largest minus smallest value)
   !> and the rms height about that plane (nm), without a copy of the heights: a tilt far
   !> above the roughness is the sample's mounting more often than its shape.
   pure subroutine plane_tilt(z, rise, roughness)
      real(dp), intent(in) :: z(:, :)
      real(dp), intent(out) :: rise, roughness
      real(dp) :: mi, mj, mz, b, c, r
      integer :: i, j
      call plane_fit(z, mz, b, c)
      mi = (size(z, 1) + 1)/2.0_dp
      mj = (size(z, 2) + 1)/2.0_dp
      rise = abs(b)*(size(z, 1) - 1) + abs(c)*(size(z, 2) - 1)
      r = 0
      do j = 1, size(z, 2)
         do i = 1, size(z, 1)
            r = r + (z(i, j) - mz - b*(i - mi) - c*(j - mj))**2
         end do
      end do
      roughness = sqrt(r/size(z))
   end subroutine plane_tilt

   !> Keep the odd/odd pixels (1, 3, 5, ...): NP -> ceil(NP/2), pixel doubles (section 4.5).
   pure function downsample_subsample(z) result(w)
      real(dp), intent(in) :: z(:, :)
      real(dp), allocatable :: w(:, :)
      w = z(1::2, 1::2)
   end function downsample_subsample

   !> Average n x n blocks: an m x m grid (m a multiple of n) -> m/n x m/n, the pixel n
   !> times larger (an AFM tip of n pixels' width; section 4.5's averaging for any n).
   pure function block_average(z, n) result(w)
      real(dp), intent(in) :: z(:, :)
      integer, intent(in) :: n
      real(dp), allocatable :: w(:, :)
      integer :: i, j, m1, m2
      m1 = size(z, 1)/n
      m2 = size(z, 2)/n
      allocate(w(m1, m2))
      do j = 1, m2
         do i = 1, m1
            w(i, j) = sum(z(n*(i - 1) + 1:n*i, n*(j - 1) + 1:n*j))/real(n, dp)**2
         end do
      end do
   end function block_average

   !> Average 2 x 2 blocks: NP -> NP/2 (NP even), pixel doubles (section 4.5).
   pure function downsample_average(z) result(w)
      real(dp), intent(in) :: z(:, :)
      real(dp), allocatable :: w(:, :)
      integer :: m
      m = size(z, 1)/2
      w = (z(1:2*m:2, 1:2*m:2) + z(2:2*m:2, 1:2*m:2) + z(1:2*m:2, 2:2*m:2) + z(2:2*m:2, 2:2*m:2))/4
   end function downsample_average
end module femcod_surfaces
