!> Surface analysis of the thesis' chapter 3: the summit search of section 3.2 with its
!> elliptic-paraboloid fits, the profile power spectral density (eq. 2.12) with the
!> fractal dimension from its slope (eq. 3.1), and the structure function (eqs.
!> 2.14-2.15). Heights z(i, j) in nm, row i along y, column j along x, pixel d in nm.
!> No I/O.
module femcod_summits
   use, intrinsic :: iso_c_binding, only: c_double_complex
   use femcod_kinds, only: dp, i8
   use femcod_arrays, only: grow
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_BAD_INPUT
   use femcod_richardson, only: power_law_fit
   use femcod_strings, only: int_str
   implicit none
   private
   public :: summit_statistics, summit_search, summits_of_size, paraboloid_fit, default_sizes, summit_power_laws
   public :: profile_psd, structure_function, psd_dimension, structure_dimension, summits_storage_bytes

   !> The summits found with neighbourhood size n (box d_n = (2n+1) L/N, eq. 3.2) in
   !> the central region common to all sizes.
   type :: summit_statistics
      integer :: n = 0
      !> Box size (nm).
      real(dp) :: box = 0
      !> Summits found, and those whose fitted paraboloid opens downwards in x and y.
      integer :: count = 0, fitted = 0
      !> Summits per um^2, mean height above the image's mean (nm), mean radius of
      !> curvature sqrt(Rx Ry) of the fitted summits (nm).
      real(dp) :: density = 0, mean_height = 0, mean_radius = 0
   end type summit_statistics

contains

   !> Neighbourhood sizes 1, 2, 3, 4, 6, 8, 11, 16, 23, 32, ... (steps of about sqrt 2)
   !> up to N/8, so that the common central region keeps three quarters of the side.
   !> The analysis' storage at its largest besides the heights (bytes), per pixel of an
   !> n1 x n2 surface: the summit search's two maps of box maxima (8 each) and its lists
   !> (row, column, height, two radii: 32 bytes a summit, at most one summit in four
   !> pixels), or the structure function's two difference maps (8 each): 24 bytes.
   pure function summits_storage_bytes(n1, n2) result(bytes)
      integer, intent(in) :: n1, n2
      integer(i8) :: bytes
      bytes = 24*int(n1, i8)*int(n2, i8)
   end function summits_storage_bytes

   pure function default_sizes(np) result(sizes)
      integer, intent(in) :: np
      integer, allocatable :: sizes(:)
      real(dp) :: s
      integer :: n
      allocate(sizes(0))
      s = 1
      do
         n = nint(s)
         if (n > max(np/8, 1)) exit
         if (size(sizes) == 0) then
            sizes = [n]
         else if (n > sizes(size(sizes))) then
            sizes = [sizes, n]
         end if
         s = s*sqrt(2.0_dp)
      end do
   end function default_sizes

   !> The summit search of section 3.2 for every size in `sizes`: a pixel is a summit
   !> of size n when it is higher than its 8 neighbours and the highest pixel of the
   !> (2n+1) x (2n+1) box around it (an equal height elsewhere in the box: the first in
   !> column order counts, so that a pair of equal peaks gives one summit). Only pixels
   !> of the central region at least max(sizes) pixels from the edge are searched, so
   !> that every size sees the same data.
   subroutine summit_search(z, pixel, sizes, stats, status)
      real(dp), intent(in) :: z(:, :), pixel
      integer, intent(in) :: sizes(:)
      type(summit_statistics), allocatable, intent(out) :: stats(:)
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: heights(:), radii(:), rx(:), ry(:)
      integer, allocatable :: rows(:), cols(:)
      integer :: k, margin, m
      real(dp) :: region
      allocate(stats(size(sizes)))
      if (size(sizes) == 0) then
         call set_error(status, STATUS_USAGE, "no neighbourhood size given")
         return
      end if
      if (any(sizes < 1)) then
         call set_error(status, STATUS_USAGE, "neighbourhood sizes must be >= 1")
         return
      end if
      margin = maxval(sizes)
      m = size(z, 1) - 2*margin
      if (m < 1 .or. size(z, 2) - 2*margin < 1) then
         call set_error(status, STATUS_USAGE, "neighbourhood size "//int_str(margin)//" leaves no central region in a "// &
            int_str(size(z, 1))//" x "//int_str(size(z, 2))//" image (largest possible: "// &
            int_str((min(size(z, 1), size(z, 2)) - 1)/2)//")")
         return
      end if
      region = real(size(z, 1) - 2*margin, dp)*(size(z, 2) - 2*margin)*pixel**2*1.0e-6_dp
      do k = 1, size(sizes)
         call summits_of_size(z, pixel, sizes(k), margin, rows, cols, heights, rx, ry)
         stats(k)%n = sizes(k)
         stats(k)%box = (2*sizes(k) + 1)*pixel
         stats(k)%count = size(rows)
         stats(k)%density = size(rows)/region
         if (size(rows) > 0) stats(k)%mean_height = sum(heights)/size(rows)
         radii = pack(sqrt(rx*ry), rx > 0 .and. ry > 0)
         stats(k)%fitted = size(radii)
         if (size(radii) > 0) stats(k)%mean_radius = sum(radii)/size(radii)
      end do
   end subroutine summit_search

   !> The summits of size n in the region `margin` pixels from the edge: their pixels,
   !> heights above the image's mean (nm), and the radii Rx, Ry (nm) of the fitted
   !> paraboloids (<= 0 where the fit does not open downwards).
   subroutine summits_of_size(z, pixel, n, margin, rows, cols, heights, rx, ry)
      real(dp), intent(in) :: z(:, :), pixel
      integer, intent(in) :: n, margin
      integer, allocatable, intent(out) :: rows(:), cols(:)
      real(dp), allocatable, intent(out) :: heights(:), rx(:), ry(:)
      real(dp), allocatable :: colmax(:, :), boxmax(:, :)
      integer :: i, j, n1, n2, cap, found
      real(dp) :: mean
      n1 = size(z, 1)
      n2 = size(z, 2)
      mean = sum(z)/size(z)
      ! Box maxima: a sliding maximum down the columns, then along the rows.
      allocate(colmax(n1, n2), boxmax(n1, n2))
      do j = 1, n2
         colmax(:, j) = sliding_max(z(:, j), n)
      end do
      do i = 1, n1
         boxmax(i, :) = sliding_max(colmax(i, :), n)
      end do
      cap = 64
      allocate(rows(cap), cols(cap))
      found = 0
      do j = margin + 1, n2 - margin
         do i = margin + 1, n1 - margin
            if (z(i, j) < boxmax(i, j)) cycle
            if (.not. is_summit(i, j)) cycle
            found = found + 1
            if (found > cap) then
               call grow(rows, 2*cap)
               call grow(cols, 2*cap)
               cap = 2*cap
            end if
            rows(found) = i
            cols(found) = j
         end do
      end do
      rows = rows(1:found)
      cols = cols(1:found)
      allocate(heights(found), rx(found), ry(found))
      do i = 1, found
         heights(i) = z(rows(i), cols(i)) - mean
         call paraboloid_fit(z, rows(i), cols(i), n, pixel, rx(i), ry(i))
      end do
   contains
      !> Higher than the 8 neighbours; no equal height earlier in the box.
      logical function is_summit(i0, j0)
         integer, intent(in) :: i0, j0
         integer :: p, q
         is_summit = .false.
         do q = j0 - 1, j0 + 1
            do p = i0 - 1, i0 + 1
               if ((p /= i0 .or. q /= j0) .and. z(p, q) >= z(i0, j0)) return
            end do
         end do
         do q = j0 - n, j0
            do p = i0 - n, i0 + n
               if (q == j0 .and. p >= i0) exit
               if (z(p, q) == z(i0, j0)) return
            end do
         end do
         is_summit = .true.
      end function is_summit
   end subroutine summits_of_size

   !> Sliding maximum over the window [k-h, k+h] (clipped at the ends) in O(n): the
   !> van Herk / Gil-Werman prefix and suffix maxima of blocks of width 2h+1.
   pure function sliding_max(a, h) result(m)
      real(dp), intent(in) :: a(:)
      integer, intent(in) :: h
      real(dp) :: m(size(a))
      real(dp), allocatable :: pre(:), suf(:), b(:)
      integer :: n, w, k, nb
      n = size(a)
      w = 2*h + 1
      nb = ((n + 2*h) + w - 1)/w*w
      ! Padded copy: b(h + k) = a(k), -huge outside.
      allocate(b(nb), pre(nb), suf(nb))
      b = -huge(1.0_dp)
      b(h + 1:h + n) = a
      do k = 1, nb
         if (mod(k - 1, w) == 0) then
            pre(k) = b(k)
         else
            pre(k) = max(pre(k - 1), b(k))
         end if
      end do
      do k = nb, 1, -1
         if (mod(k, w) == 0 .or. k == nb) then
            suf(k) = b(k)
         else
            suf(k) = max(suf(k + 1), b(k))
         end if
      end do
      ! Window of a(k) is b(k .. k + 2h).
      do k = 1, n
         m(k) = max(suf(k), pre(k + 2*h))
      end do
   end function sliding_max

   !> Least-squares elliptic paraboloid with axes along x and y and its maximum fixed
   !> at the summit (i, j): z = z0 - x^2/(2 Rx) - y^2/(2 Ry) over the (2n+1)^2 box.
   !> Rx, Ry in nm; a direction that does not curve downwards gives a radius <= 0
   !> (-1 when the fit is singular).
   pure subroutine paraboloid_fit(z, i, j, n, pixel, rx, ry)
      real(dp), intent(in) :: z(:, :), pixel
      integer, intent(in) :: i, j, n
      real(dp), intent(out) :: rx, ry
      real(dp) :: sxx, sxy, syy, bx, by, x2, y2, d, det, a, b
      integer :: p, q
      sxx = 0; sxy = 0; syy = 0; bx = 0; by = 0
      do q = -n, n
         x2 = (q*pixel)**2
         do p = -n, n
            y2 = (p*pixel)**2
            d = z(i, j) - z(i + p, j + q)
            sxx = sxx + x2*x2
            sxy = sxy + x2*y2
            syy = syy + y2*y2
            bx = bx + d*x2
            by = by + d*y2
         end do
      end do
      det = sxx*syy - sxy*sxy
      rx = -1
      ry = -1
      if (det <= 0) return
      a = (bx*syy - by*sxy)/det
      b = (by*sxx - bx*sxy)/det
      rx = 0
      ry = 0
      if (a > 0) rx = 1/(2*a)
      if (b > 0) ry = 1/(2*b)
   end subroutine paraboloid_fit

   !> Power laws against the box size d (nm), least squares in log-log over the sizes:
   !> (1) density ~ d^e1, (2) mean height ~ d^e2, (3) mean radius ~ d^e3.
   pure subroutine summit_power_laws(stats, exponents, prefactors)
      type(summit_statistics), intent(in) :: stats(:)
      real(dp), intent(out) :: exponents(3), prefactors(3)
      real(dp) :: box(size(stats)), v(size(stats))
      integer :: k
      do k = 1, size(stats)
         box(k) = stats(k)%box
      end do
      do k = 1, size(stats)
         v(k) = stats(k)%density
      end do
      call power_law_fit(box, v, exponents(1), prefactors(1))
      do k = 1, size(stats)
         v(k) = stats(k)%mean_height
      end do
      call power_law_fit(box, v, exponents(2), prefactors(2))
      do k = 1, size(stats)
         v(k) = stats(k)%mean_radius
      end do
      call power_law_fit(box, v, exponents(3), prefactors(3))
   end subroutine summit_power_laws

   !> Profile power spectral density of eq. 2.12, P(w) = |int_0^L z e^(-i w x) dx|^2 / L,
   !> averaged over every row and every column (each profile's mean removed):
   !> P_k = (d/N) |Z_k|^2 (nm^3) at the frequencies f_k = k/L (1/nm), k = 1 .. N/2.
   subroutine profile_psd(z, pixel, frequency, power)
      use femcod_convolution, only: line_transform, line_transform_setup, line_transform_apply, line_transform_free
      real(dp), intent(in) :: z(:, :), pixel
      real(dp), allocatable, intent(out) :: frequency(:), power(:)
      real(dp), allocatable :: line(:)
      complex(c_double_complex), allocatable :: spec(:)
      type(line_transform) :: plan
      integer :: n, k, p, np2
      n = size(z, 1)
      np2 = n/2
      allocate(line(n), spec(n/2 + 1), frequency(np2), power(np2))
      frequency = [(k/(n*pixel), k = 1, np2)]
      power = 0
      call line_transform_setup(plan, line, spec)
      do p = 1, n
         line = z(:, p) - sum(z(:, p))/n
         call line_transform_apply(plan, line, spec)
         power = power + abs(spec(2:np2 + 1))**2
         line = z(p, :) - sum(z(p, :))/n
         call line_transform_apply(plan, line, spec)
         power = power + abs(spec(2:np2 + 1))**2
      end do
      call line_transform_free(plan)
      power = power/(2*n)*pixel/n
   end subroutine profile_psd

   !> Structure function of eq. 2.14, S(tau) = <(z(x + tau) - z(x))^2> (nm^2), along
   !> rows and columns, at tau = k d for k = 1 .. maxlag.
   pure subroutine structure_function(z, pixel, maxlag, tau, s)
      real(dp), intent(in) :: z(:, :), pixel
      integer, intent(in) :: maxlag
      real(dp), allocatable, intent(out) :: tau(:), s(:)
      integer :: k, n1, n2
      n1 = size(z, 1)
      n2 = size(z, 2)
      allocate(tau(maxlag), s(maxlag))
      do k = 1, maxlag
         tau(k) = k*pixel
         s(k) = (sum((z(1 + k:, :) - z(:n1 - k, :))**2) + sum((z(:, 1 + k:) - z(:, :n2 - k))**2))/ &
            ((n1 - k)*n2 + n1*(n2 - k))
      end do
   end subroutine structure_function

   !> Profile fractal dimension from the PSD slope over [fmin, fmax] (eq. 3.1:
   !> P ~ w^-(5 - 2D), so D = (5 + slope)/2; the surface's is Ds = D + 1).
   pure subroutine psd_dimension(frequency, power, fmin, fmax, dimension, slope, points)
      real(dp), intent(in) :: frequency(:), power(:), fmin, fmax
      real(dp), intent(out) :: dimension, slope
      !> The frequencies in [fmin, fmax]: below 2 the dimension is not determined (0 and
      !> slope 0 are returned; the grid is too small for the range).
      integer, intent(out), optional :: points
      real(dp) :: pre
      logical :: keep(size(frequency))
      keep = frequency >= fmin .and. frequency <= fmax
      if (present(points)) points = count(keep)
      dimension = 0
      slope = 0
      if (count(keep) < 2) return
      call power_law_fit(pack(frequency, keep), pack(power, keep), slope, pre)
      dimension = (5 + slope)/2
   end subroutine psd_dimension

   !> Profile fractal dimension and roughness G from the structure function over
   !> [tmin, tmax] (eq. 2.15: S = G^(2(D-1)) tau^(2(2-D)), so D = 2 - slope/2 and
   !> G = prefactor^(1/(2(D-1))), nm).
   pure subroutine structure_dimension(tau, s, tmin, tmax, dimension, g, points)
      real(dp), intent(in) :: tau(:), s(:), tmin, tmax
      real(dp), intent(out) :: dimension, g
      !> The lags in [tmin, tmax]: below 2 the dimension is not determined (0 returned).
      integer, intent(out), optional :: points
      real(dp) :: slope, pre
      logical :: keep(size(tau))
      keep = tau >= tmin .and. tau <= tmax
      if (present(points)) points = count(keep)
      dimension = 0
      g = 0
      if (count(keep) < 2) return
      call power_law_fit(pack(tau, keep), pack(s, keep), slope, pre)
      dimension = 2 - slope/2
      g = 0
      if (dimension > 1 .and. pre > 0) g = pre**(1/(2*(dimension - 1)))
   end subroutine structure_dimension
end module femcod_summits
