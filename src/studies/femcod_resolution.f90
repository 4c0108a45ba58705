!> The estimates of the thesis' resolution study (section 4.5) that need no contact
!> solve: the uncoupled voxel model, McCool's Greenwood-Williamson estimate, and the
!> Richardson extrapolation of an area-load curve between two resolutions. Lengths in
!> nm, loads in nN, moduli and pressures in GPa (nN/nm^2). No I/O.
module femcod_resolution
   use femcod_kinds, only: dp
   use femcod_sort, only: merge_sort_index
   use femcod_richardson, only: richardson_extrapolate
   implicit none
   private
   public :: uncoupled_curve, mccool_parameters, mccool_surface, mccool_area, interpolate_area, &
      richardson_area, gw_integral

   real(dp), parameter :: pi = acos(-1.0_dp)

   !> McCool's summit statistics of an isotropic Gaussian surface from its spectral
   !> moments (McCool 1986, Wear 107; thesis ref. [4.2]):
   !>   m0 = variance of heights, m2 = mean squared slope, m4 = mean squared curvature
   !>   (profile values, averaged over the x and y directions), alpha = m0 m4 / m2^2,
   !>   summit density  eta   = m4 / (6 pi sqrt(3) m2)            (1/nm^2)
   !>   summit radius   R     = 0.375 sqrt(pi / m4)                (nm)
   !>   summit heights  sigma = sqrt((1 - 0.8968/alpha) m0)        (nm)
   type :: mccool_parameters
      real(dp) :: m0 = 0, m2 = 0, m4 = 0, alpha = 0
      real(dp) :: density = 0, radius = 0, sigma = 0
   end type mccool_parameters

contains

   !> The uncoupled voxel model (thesis Fig. 4.17, dashed): a rigid substrate under
   !> independent voxel springs of compliance `compliance` (nm/nN, the single-pixel
   !> compliance of the Boussinesq element). At approach d every pixel with initial gap
   !> g < d carries (d - g)/compliance, so
   !>   load(d) = sum_{g<d} (d - g) / compliance,   area(d) = #{g < d} pixel^2.
   !> `gaps` are the initial gaps (nm); O((npix + nd) log npix) by sorting once.
   pure subroutine uncoupled_curve(gaps, compliance, pixel, approach, load, area)
      real(dp), intent(in) :: gaps(:), compliance, pixel, approach(:)
      real(dp), intent(out) :: load(:), area(:)
      integer, allocatable :: order(:)
      real(dp), allocatable :: g(:), prefix(:)
      integer :: k, lo, hi, mid, n
      allocate(order(size(gaps)))
      call merge_sort_index(gaps, order)
      g = gaps(order)
      allocate(prefix(0:size(g)))
      prefix(0) = 0
      do k = 1, size(g)
         prefix(k) = prefix(k - 1) + g(k)
      end do
      do k = 1, size(approach)
         ! n = number of gaps strictly below the approach (binary search).
         lo = 0
         hi = size(g)
         do while (lo < hi)
            mid = (lo + hi + 1)/2
            if (g(mid) < approach(k)) then
               lo = mid
            else
               hi = mid - 1
            end if
         end do
         n = lo
         load(k) = (n*approach(k) - prefix(n))/compliance
         area(k) = n*pixel**2
      end do
   end subroutine uncoupled_curve

   !> McCool's parameters of the height map `z` (nm) with pixel `pixel` (nm): moments
   !> from forward first and second differences along rows and columns.
   pure function mccool_surface(z, pixel) result(p)
      real(dp), intent(in) :: z(:, :), pixel
      type(mccool_parameters) :: p
      real(dp) :: mean, s2, s4
      integer :: n1, n2
      n1 = size(z, 1)
      n2 = size(z, 2)
      mean = sum(z)/size(z)
      p%m0 = sum((z - mean)**2)/size(z)
      s2 = 0
      s4 = 0
      if (n1 >= 3 .and. n2 >= 3) then
         s2 = (sum((z(2:, :) - z(:n1 - 1, :))**2)/((n1 - 1)*n2) + &
            sum((z(:, 2:) - z(:, :n2 - 1))**2)/(n1*(n2 - 1)))/(2*pixel**2)
         s4 = (sum((z(3:, :) - 2*z(2:n1 - 1, :) + z(:n1 - 2, :))**2)/((n1 - 2)*n2) + &
            sum((z(:, 3:) - 2*z(:, 2:n2 - 1) + z(:, :n2 - 2))**2)/(n1*(n2 - 2)))/(2*pixel**4)
      end if
      p%m2 = s2
      p%m4 = s4
      if (s2 > 0 .and. s4 > 0) then
         p%alpha = p%m0*p%m4/p%m2**2
         p%density = p%m4/(6*pi*sqrt(3.0_dp)*p%m2)
         p%radius = 0.375_dp*sqrt(pi/p%m4)
         p%sigma = sqrt(max(1 - 0.8968_dp/p%alpha, 0.0_dp)*p%m0)
      end if
   end function mccool_surface

   !> Greenwood-Williamson integral F_n(h) = int_h^inf (s - h)^n phi(s) ds for the
   !> standard normal density phi, n = 1 or 3/2 (written s = h + u^2, Simpson's rule
   !> on u in [0, sqrt(max(12 - h, 0))], 2000 panels: relative error below 1e-10).
   pure real(dp) function gw_integral(n, h)
      real(dp), intent(in) :: n, h
      integer, parameter :: panels = 2000
      real(dp) :: umax, du, u, wgt
      integer :: k
      gw_integral = 0
      umax = sqrt(max(12 - h, 0.0_dp))
      if (umax <= 0) return
      du = umax/panels
      do k = 0, panels
         u = k*du
         wgt = 2
         if (mod(k, 2) == 1) wgt = 4
         if (k == 0 .or. k == panels) wgt = 1
         ! (s - h)^n ds = u^(2n) 2u du
         gw_integral = gw_integral + wgt*2*u**(2*n + 1)*exp(-(h + u*u)**2/2)
      end do
      gw_integral = gw_integral*du/3/sqrt(2*pi)
   end function gw_integral

   !> McCool's Greenwood-Williamson area (nm^2) at each nominal pressure `pressure`
   !> (GPa) on a nominal area `nominal` (nm^2):
   !>   A/A0 = pi eta R sigma F_1(h),   p = (4/3) eta E* sqrt(R) sigma^(3/2) F_3/2(h),
   !> h the separation from the mean summit height over sigma. h(p) is found on a table
   !> of 1301 separations in [-5, 8] with log-log interpolation (the curve is smooth
   !> and monotone there). Pressures above the table's range give the table's end.
   pure subroutine mccool_area(p, estar, nominal, pressure, area)
      type(mccool_parameters), intent(in) :: p
      real(dp), intent(in) :: estar, nominal, pressure(:)
      real(dp), intent(out) :: area(:)
      integer, parameter :: nt = 1301
      real(dp) :: hs(nt), lp(nt), la(nt), t, x
      integer :: k, lo, hi
      area = 0
      if (p%density <= 0 .or. p%sigma <= 0) return
      do k = 1, nt
         ! From h = 8 (lowest pressure) to h = -5, so that lp increases with k.
         hs(k) = 8 - 13*real(k - 1, dp)/(nt - 1)
         lp(k) = log(4.0_dp/3*p%density*estar*sqrt(p%radius)*p%sigma**1.5_dp*gw_integral(1.5_dp, hs(k)))
         la(k) = log(pi*p%density*p%radius*p%sigma*gw_integral(1.0_dp, hs(k))*nominal)
      end do
      do k = 1, size(pressure)
         if (pressure(k) <= 0) cycle
         x = log(pressure(k))
         if (x <= lp(1)) then
            area(k) = exp(la(1) + (x - lp(1))*(la(2) - la(1))/(lp(2) - lp(1)))
            cycle
         end if
         if (x >= lp(nt)) then
            area(k) = exp(la(nt))
            cycle
         end if
         lo = bracket(lp, x)
         hi = lo + 1
         t = (x - lp(lo))/(lp(hi) - lp(lo))
         area(k) = exp(la(lo) + t*(la(hi) - la(lo)))
      end do
   end subroutine mccool_area

   !> Area of a history (loads increasing, areas at the end of each step) at `load` by
   !> linear interpolation between steps; -1 outside the history's load range.
   pure real(dp) function interpolate_area(loads, areas, load)
      real(dp), intent(in) :: loads(:), areas(:), load
      integer :: lo, hi
      interpolate_area = -1
      if (size(loads) == 0) return
      if (load < loads(1) .or. load > loads(size(loads))) return
      if (size(loads) == 1) then
         interpolate_area = areas(1)
         return
      end if
      lo = bracket(loads, load)
      hi = lo + 1
      if (loads(hi) == loads(lo)) then
         interpolate_area = areas(hi)
      else
         interpolate_area = areas(lo) + (load - loads(lo))/(loads(hi) - loads(lo))*(areas(hi) - areas(lo))
      end if
   end function interpolate_area

   !> The interval of an ascending table (at least two entries) that holds x: the index lo
   !> in 1..n-1 with table(lo) <= x <= table(lo + 1), by bisection (the last such lo when
   !> x equals an entry); x outside the table gives the end interval on its side.
   pure integer function bracket(table, x) result(lo)
      real(dp), intent(in) :: table(:), x
      integer :: hi, mid
      lo = 1
      hi = size(table)
      do while (hi - lo > 1)
         mid = (lo + hi)/2
         if (table(mid) <= x) then
            lo = mid
         else
            hi = mid
         end if
      end do
   end function bracket

   !> Richardson extrapolation of the area at the fine image's loads (thesis Fig. 4.18b):
   !> A = (r^p A_fine - A_coarse)/(r^p - 1) with r = np_fine/np_coarse and rate p
   !> (the thesis takes p = 1), the coarse area interpolated at the same load. Loads
   !> outside the coarse history's range are left out (`keep` false).
   pure subroutine richardson_area(coarse_load, coarse_area, fine_load, fine_area, ratio, rate, area, keep)
      real(dp), intent(in) :: coarse_load(:), coarse_area(:), fine_load(:), fine_area(:), ratio, rate
      real(dp), intent(out) :: area(:)
      logical, intent(out) :: keep(:)
      real(dp) :: ac
      integer :: k
      do k = 1, size(fine_load)
         ac = interpolate_area(coarse_load, coarse_area, fine_load(k))
         keep(k) = ac >= 0
         area(k) = 0
         if (keep(k)) area(k) = richardson_extrapolate(ac, fine_area(k), ratio, rate)
      end do
   end subroutine richardson_area
end module femcod_resolution
