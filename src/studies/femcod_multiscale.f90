!> The hierarchical multiscale Hertz model of the thesis' section 3.3. A roughness
!> template (summit heights and radii found with box size d1, their density) is
!> scaled to finer length scales d_k = d1 / s^(k-1) with the power laws of the summit
!> search: heights ~ d^eh, radii ~ d^eR, density ~ d^eN. At the first scale the
!> template is pressed against a rigid flat by the total load (eq. 3.9); the load of
!> every contacting asperity is shared among the asperities of the next scale that sit
!> on its contact (eqs. 3.11-3.12), and so on. Each asperity follows Hertz (eq. 3.13):
!>   F = (4/3) E* sqrt(R) w^(3/2),   A = pi R w   (w: its interference).
!> How many finer asperities a host carries (section 3.3.1):
!>   "close-packed": as many of the tallest as fit on the host's contact when their
!>                   contact spots are hexagonally close-packed (sum of spot areas
!>                   <= pi/(2 sqrt 3) of the host's contact area), at least one;
!>   "density":      the host's contact area times the finer scale's summit density
!>                   (the experimental asperity-density constraint), at least one.
!> Lengths nm, loads nN, E* GPa, areas nm^2. No I/O.
module femcod_multiscale
   use femcod_kinds, only: dp
   use femcod_arrays, only: grow
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_NUMERICAL, STATUS_BAD_INPUT
   use femcod_sort, only: merge_sort_index
   use femcod_strings, only: int_str, sig_str
   implicit none
   private
   public :: roughness_template, multiscale_result, multiscale_hertz, share_load, hertz_area, MAX_CONTACTS_PER_SCALE, &
      check_growth

   real(dp), parameter :: pi = acos(-1.0_dp)
   !> Hexagonal close packing of equal circles: the covered fraction pi/(2 sqrt 3).
   real(dp), parameter :: hex_fraction = pi/(2*sqrt(3.0_dp))
   !> The model refuses to follow more contacts than this at one scale.
   integer, parameter :: MAX_CONTACTS_PER_SCALE = 20000000

   !> The roughness template: summit heights and radii (nm), tallest first, found with
   !> box size `box` (nm), and the summit density there (1/nm^2).
   type :: roughness_template
      real(dp), allocatable :: heights(:), radii(:)
      real(dp) :: box = 0, density = 0
   end type roughness_template

   !> Per scale k = 1 .. K: the box size d_k (nm), the true contact area (nm^2) and the
   !> number of contacting asperities.
   type :: multiscale_result
      real(dp), allocatable :: length(:), area(:)
      integer, allocatable :: contacts(:)
   end type multiscale_result

contains

   !> Hertz contact area of a sphere of radius `radius` under `load` (eq. 3.13):
   !> A = pi (3 F R / (4 E*))^(2/3).
   elemental real(dp) function hertz_area(radius, load, estar)
      real(dp), intent(in) :: radius, load, estar
      hertz_area = pi*(3*load*radius/(4*estar))**(2.0_dp/3)
   end function hertz_area

   !> Share `load` among asperities of heights h (tallest first) and radii r pressed by
   !> a rigid flat: the approach delta with sum_i (4/3) E* sqrt(r_i) w_i^(3/2) = load,
   !> w_i = max(h_i - h_1 + delta, 0), by bisection to round-off. Returns each
   !> asperity's force and contact area.
   pure subroutine share_load(h, r, load, estar, force, area)
      real(dp), intent(in) :: h(:), r(:), load, estar
      real(dp), intent(out) :: force(:), area(:)
      real(dp) :: lo, hi, mid
      integer :: it
      force = 0
      area = 0
      if (load <= 0 .or. size(h) == 0) return
      lo = 0
      hi = (3*load/(4*estar*sqrt(r(1))))**(2.0_dp/3)
      ! The tallest alone needs `hi`; more asperities need less, so [0, hi] brackets.
      do it = 1, 200
         mid = (lo + hi)/2
         if (mid <= lo .or. mid >= hi) exit
         if (total(mid) < load) then
            lo = mid
         else
            hi = mid
         end if
      end do
      force = 4.0_dp/3*estar*sqrt(r)*max(h - h(1) + hi, 0.0_dp)**1.5_dp
      ! Exact total: scale the forces (the bisection leaves a relative 1e-16).
      if (sum(force) > 0) force = force*(load/sum(force))
      where (force > 0) area = pi*r*max(h - h(1) + hi, 0.0_dp)
   contains
      pure real(dp) function total(delta)
         real(dp), intent(in) :: delta
         total = sum(4.0_dp/3*estar*sqrt(r)*max(h - h(1) + delta, 0.0_dp)**1.5_dp)
      end function total
   end subroutine share_load

   !> The contacts multiply by about the same factor at every scale (the model is
   !> self-similar): from `previous` contacts at scale k - 1 and `current` at scale k,
   !> refuse (exit 4) a run whose last scale would pass MAX_CONTACTS_PER_SCALE, before
   !> the hours that reaching it takes, naming the scales that fit.
   subroutine check_growth(previous, current, k, scales, status)
      integer, intent(in) :: previous, current, k, scales
      type(status_type), intent(inout) :: status
      real(dp) :: growth, projected
      if (status%code /= 0 .or. previous <= 0 .or. current <= previous .or. scales <= k) return
      growth = real(current, dp)/previous
      projected = current*growth**(scales - k)
      if (projected <= MAX_CONTACTS_PER_SCALE) return
      call set_error(status, STATUS_NUMERICAL, "the contacts grow "//sig_str(growth, 3)//" times a scale ("// &
         int_str(previous)//" to "//int_str(current)//" at scales "//int_str(k - 1)//" and "//int_str(k)// &
         "): about "//sig_str(projected, 2)//" at scale "//int_str(scales)//", beyond the "// &
         int_str(MAX_CONTACTS_PER_SCALE)//" a scale this model holds; use at most "// &
         int_str(k + max(0, floor(log(real(MAX_CONTACTS_PER_SCALE, dp)/current)/log(growth))))// &
         " scales (--scales) or a larger scaling constant (--s)")
   end subroutine check_growth

   !> The multiscale model with length scaling constant s > 1 over `scales` scales,
   !> heights/radii/density exponents eh, eR, eN, total load `load` and modulus estar.
   subroutine multiscale_hertz(template, eh, er, en, s, scales, load, estar, constraint, result, status)
      type(roughness_template), intent(in) :: template
      real(dp), intent(in) :: eh, er, en, s, load, estar
      integer, intent(in) :: scales
      character(len=*), intent(in) :: constraint
      type(multiscale_result), intent(out) :: result
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: hf(:), ha(:), nf(:), na(:), h(:), r(:), f(:), a(:), hk(:), rk(:)
      integer, allocatable :: order(:)
      real(dp) :: ratio, density
      integer :: k, i, nt, nh, m, found
      if (status%code /= 0) return
      nt = size(template%heights)
      if (nt == 0 .or. size(template%radii) /= nt) then
         call set_error(status, STATUS_BAD_INPUT, "the roughness template has no summits: the surface has none "// &
            "at that neighbourhood size (--template-size or --sizes)")
         return
      end if
      if (.not. (s > 1) .or. scales < 1 .or. .not. (load > 0) .or. .not. (estar > 0) .or. any(template%radii <= 0)) then
         call set_error(status, STATUS_USAGE, "multiscale model needs s > 1, scales >= 1, load > 0, E* > 0 and "// &
            "positive radii")
         return
      end if
      if (constraint /= "close-packed" .and. constraint /= "density") then
         call set_error(status, STATUS_USAGE, "constraint must be close-packed or density, found '"//constraint//"'")
         return
      end if
      ! The template, tallest first.
      allocate(order(nt))
      call merge_sort_index(-template%heights, order)
      h = template%heights(order)
      r = template%radii(order)
      allocate(result%length(scales), result%area(scales), result%contacts(scales))
      ! Scale 1: the whole template carries the load.
      allocate(f(nt), a(nt))
      call share_load(h, r, load, estar, f, a)
      hf = pack(f, f > 0)
      ha = pack(a, f > 0)
      result%length(1) = template%box
      result%area(1) = sum(ha)
      result%contacts(1) = size(hf)
      do k = 2, scales
         ! The template at scale k: d_k = d_1 / s^(k-1).
         ratio = s**(-(k - 1))
         result%length(k) = template%box*ratio
         density = template%density*ratio**en
         ! The template at this scale, once for all hosts.
         hk = h*ratio**eh
         rk = r*ratio**er
         allocate(nf(max(16, size(hf))), na(max(16, size(hf))))
         found = 0
         do i = 1, size(hf)
            nh = hosted(constraint, ha(i), hf(i), hk, rk, density, estar)
            deallocate(f, a)
            allocate(f(nh), a(nh))
            call share_load(hk(1:nh), rk(1:nh), hf(i), estar, f, a)
            m = count(f > 0)
            if (found + m > MAX_CONTACTS_PER_SCALE) then
               call set_error(status, STATUS_NUMERICAL, "more than "//int_str(MAX_CONTACTS_PER_SCALE)// &
                  " contacts at scale "//int_str(k)//"; use fewer scales or a larger scaling constant")
               return
            end if
            if (found + m > size(nf)) then
               call grow(nf, 2*(found + m))
               call grow(na, 2*(found + m))
            end if
            nf(found + 1:found + m) = pack(f, f > 0)
            na(found + 1:found + m) = pack(a, f > 0)
            found = found + m
         end do
         hf = nf(1:found)
         ha = na(1:found)
         deallocate(nf, na)
         result%area(k) = sum(ha)
         result%contacts(k) = size(hf)
         if (k < scales) call check_growth(result%contacts(k - 1), result%contacts(k), k, scales, status)
         if (status%code /= 0) return
      end do
   end subroutine multiscale_hertz

   !> How many of the tallest finer asperities (heights hs, radii rs) a host of contact
   !> area `host_area` and load `host_load` carries under `constraint`.
   pure integer function hosted(constraint, host_area, host_load, hs, rs, dens, estar) result(n)
      character(len=*), intent(in) :: constraint
      real(dp), intent(in) :: host_area, host_load, hs(:), rs(:), dens, estar
      real(dp) :: ff(size(hs)), aa(size(hs))
      integer :: lo, hi, mid, nt
      nt = size(hs)
      if (constraint == "density") then
         n = int(min(real(nt, dp), max(1.0_dp, host_area*dens)))
         return
      end if
      ! Close-packed: the largest n whose contact spots fit (bisection on n; more
      ! asperities share the load, so their spots shrink).
      call share_load(hs, rs, host_load, estar, ff, aa)
      if (sum(aa) <= hex_fraction*host_area) then
         n = nt
         return
      end if
      lo = 1
      hi = nt
      do while (hi - lo > 1)
         mid = (lo + hi)/2
         call share_load(hs(1:mid), rs(1:mid), host_load, estar, ff(1:mid), aa(1:mid))
         if (sum(aa(1:mid)) <= hex_fraction*host_area) then
            lo = mid
         else
            hi = mid
         end if
      end do
      n = lo
   end function hosted
end module femcod_multiscale
