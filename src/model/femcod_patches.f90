!> Contact patches: the connected groups of contact pixels of one state, as the field's
!> studies count them (and tamaas' cluster tools): 4-connected (pixels sharing a side) and
!> 8-connected (also a corner), each patch's area in pixels and its perimeter in pixel
!> sides (the sides a contact pixel shares with a pixel out of contact, or with the edge of
!> a free grid; a periodic cell wraps, so a patch may cross its edges). The perimeter of
!> a patch is the same for both connectivities: 8-connected patches are unions of
!> 4-connected ones. No I/O.
module femcod_patches
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use femcod_kinds, only: dp
   implicit none
   private
   public :: contact_patches, find_patches, label_patches, perimeter_area_fit

   !> The patches of one contact map.
   type :: contact_patches
      !> The number of 4- and 8-connected patches.
      integer :: count4 = 0, count8 = 0
      !> Each patch's area (pixels) and perimeter (pixel sides), in the order of its first
      !> pixel in column order.
      integer, allocatable :: area4(:), perimeter4(:), area8(:), perimeter8(:)
   end type contact_patches

contains

   !> The patches of the contact pixels (rows `i`, columns `j`) of an NP x NP grid.
   subroutine find_patches(np, i, j, periodic, patches)
      integer, intent(in) :: np, i(:), j(:)
      logical, intent(in) :: periodic
      type(contact_patches), intent(out) :: patches
      logical, allocatable :: mask(:, :)
      integer, allocatable :: labels(:, :)
      allocate(mask(np, np))
      mask = .false.
      call mark(mask, i, j)
      allocate(labels(np, np))
      call label_patches(mask, periodic, .false., labels, patches%count4)
      call patch_measures(mask, labels, patches%count4, periodic, patches%area4, patches%perimeter4)
      call label_patches(mask, periodic, .true., labels, patches%count8)
      call patch_measures(mask, labels, patches%count8, periodic, patches%area8, patches%perimeter8)
   end subroutine find_patches

   pure subroutine mark(mask, i, j)
      logical, intent(inout) :: mask(:, :)
      integer, intent(in) :: i(:), j(:)
      integer :: k
      do k = 1, size(i)
         mask(i(k), j(k)) = .true.
      end do
   end subroutine mark

   !> Label the connected groups of `mask` 1, 2, ... in the order of their first pixel in
   !> column order (0 off contact): a flood fill with an explicit stack, O(NP^2).
   subroutine label_patches(mask, periodic, diagonal, labels, found, wrap_columns)
      logical, intent(in) :: mask(:, :)
      !> The grid wraps (a periodic cell); corners connect too (8-connected).
      logical, intent(in) :: periodic, diagonal
      integer, intent(out) :: labels(:, :)
      !> The number of patches.
      integer, intent(out) :: found
      !> Whether the columns wrap too (default: as `periodic`; a slab of columns of a
      !> periodic cell wraps in its rows only).
      logical, intent(in), optional :: wrap_columns
      integer, allocatable :: stack(:)
      integer :: n1, n2, i, j, top, p, pi, pj, di, dj, qi, qj
      logical :: wrap_j
      wrap_j = periodic
      if (present(wrap_columns)) wrap_j = wrap_columns
      n1 = size(mask, 1)
      n2 = size(mask, 2)
      labels = 0
      found = 0
      allocate(stack(max(1, count(mask))))
      do j = 1, n2
         do i = 1, n1
            if (.not. mask(i, j) .or. labels(i, j) /= 0) cycle
            found = found + 1
            labels(i, j) = found
            top = 1
            stack(1) = (j - 1)*n1 + i
            do while (top > 0)
               p = stack(top)
               top = top - 1
               pj = (p - 1)/n1 + 1
               pi = p - (pj - 1)*n1
               do dj = -1, 1
                  do di = -1, 1
                     if (di == 0 .and. dj == 0) cycle
                     if (.not. diagonal .and. di /= 0 .and. dj /= 0) cycle
                     qi = pi + di
                     qj = pj + dj
                     if (periodic) qi = modulo(qi - 1, n1) + 1
                     if (wrap_j) qj = modulo(qj - 1, n2) + 1
                     if (qi < 1 .or. qi > n1 .or. qj < 1 .or. qj > n2) cycle
                     if (.not. mask(qi, qj) .or. labels(qi, qj) /= 0) cycle
                     labels(qi, qj) = found
                     top = top + 1
                     stack(top) = (qj - 1)*n1 + qi
                  end do
               end do
            end do
         end do
      end do
   end subroutine label_patches

   !> Each labelled patch's area (pixels) and perimeter (pixel sides facing no contact).
   pure subroutine patch_measures(mask, labels, count, periodic, area, perimeter)
      logical, intent(in) :: mask(:, :)
      integer, intent(in) :: labels(:, :), count
      logical, intent(in) :: periodic
      integer, allocatable, intent(out) :: area(:), perimeter(:)
      integer :: n1, n2, i, j, k, qi, qj, side
      integer, parameter :: DI(4) = [1, -1, 0, 0], DJ(4) = [0, 0, 1, -1]
      n1 = size(mask, 1)
      n2 = size(mask, 2)
      allocate(area(count), perimeter(count))
      area = 0
      perimeter = 0
      do j = 1, n2
         do i = 1, n1
            k = labels(i, j)
            if (k == 0) cycle
            area(k) = area(k) + 1
            do side = 1, 4
               qi = i + DI(side)
               qj = j + DJ(side)
               if (periodic) then
                  qi = modulo(qi - 1, n1) + 1
                  qj = modulo(qj - 1, n2) + 1
               else if (qi < 1 .or. qi > n1 .or. qj < 1 .or. qj > n2) then
                  perimeter(k) = perimeter(k) + 1
                  cycle
               end if
               if (.not. mask(qi, qj)) perimeter(k) = perimeter(k) + 1
            end do
         end do
      end do
   end subroutine patch_measures

   !> The perimeter-area relation over the patches: the least-squares line of
   !> log(perimeter) against log(area), perimeter = prefactor area^exponent (a compact
   !> patch gives 1/2, a fractal boundary more). NaN with fewer than two patch sizes.
   pure subroutine perimeter_area_fit(area, perimeter, exponent, prefactor)
      integer, intent(in) :: area(:), perimeter(:)
      real(dp), intent(out) :: exponent, prefactor
      real(dp) :: x(size(area)), y(size(area)), mx, my
      exponent = ieee_value(1.0_dp, ieee_quiet_nan)
      prefactor = exponent
      if (size(area) < 2) return
      if (all(area == area(1))) return
      x = log(real(area, dp))
      y = log(real(perimeter, dp))
      mx = sum(x)/size(x)
      my = sum(y)/size(y)
      exponent = sum((x - mx)*(y - my))/sum((x - mx)**2)
      prefactor = exp(my - exponent*mx)
   end subroutine perimeter_area_fit
end module femcod_patches
