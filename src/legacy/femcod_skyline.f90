!> Skyline (compact column) storage of FEMCOD: COLHT column heights, diagonal
!> addresses (IPIADR) and assembly of element matrices.
!>
!> Column j holds rows j - height(j) .. j, stored top to diagonal; `iadr(j)` is the
!> address of the diagonal, so row i of column j is at iadr(j) - (j - i) and column j
!> starts at iadr(j-1) + 1 (iadr(0) = 0). Equation number 0 marks a fixed d.o.f.
module femcod_skyline
   use femcod_kinds, only: dp
   implicit none
   private
   public :: colht, diagonal_addresses, assemble_element, skyline_matvec

contains

   !> COLHT: raise the column heights for one element with equation numbers `eqs`
   !> (0 = fixed, ignored): every column reaches up to the element's smallest equation.
   pure subroutine colht(eqs, height)
      integer, intent(in) :: eqs(:)
      integer, intent(inout) :: height(:)
      integer :: k, top
      top = huge(top)
      do k = 1, size(eqs)
         if (eqs(k) > 0) top = min(top, eqs(k))
      end do
      do k = 1, size(eqs)
         if (eqs(k) > 0) height(eqs(k)) = max(height(eqs(k)), eqs(k) - top)
      end do
   end subroutine colht

   !> Diagonal addresses from column heights; iadr(n) is the storage size.
   pure subroutine diagonal_addresses(height, iadr)
      integer, intent(in) :: height(:)
      integer, intent(out) :: iadr(:)
      integer :: j
      iadr(1) = 1
      do j = 2, size(height)
         iadr(j) = iadr(j - 1) + height(j) + 1
      end do
   end subroutine diagonal_addresses

   !> Add the upper triangle of a symmetric element matrix into skyline storage.
   pure subroutine assemble_element(element, eqs, iadr, a)
      real(dp), intent(in) :: element(:, :)
      integer, intent(in) :: eqs(:), iadr(:)
      real(dp), intent(inout) :: a(:)
      integer :: k, l, i, j
      do l = 1, size(eqs)
         j = eqs(l)
         if (j <= 0) cycle
         do k = 1, size(eqs)
            i = eqs(k)
            if (i <= 0 .or. i > j) cycle
            a(iadr(j) - (j - i)) = a(iadr(j) - (j - i)) + element(k, l)
         end do
      end do
   end subroutine assemble_element

   !> y = K x for a symmetric matrix in skyline storage (upper triangle by columns).
   pure subroutine skyline_matvec(a, iadr, x, y)
      real(dp), intent(in) :: a(:), x(:)
      integer, intent(in) :: iadr(:)
      real(dp), intent(out) :: y(:)
      integer :: j, top, len, first
      y = 0
      do j = 1, size(iadr)
         if (j == 1) then
            len = 0
         else
            len = iadr(j) - iadr(j - 1) - 1
         end if
         top = j - len
         first = iadr(j) - len
         y(j) = y(j) + a(iadr(j))*x(j)
         if (len > 0) then
            y(top:j - 1) = y(top:j - 1) + a(first:iadr(j) - 1)*x(j)
            y(j) = y(j) + dot_product(a(first:iadr(j) - 1), x(top:j - 1))
         end if
      end do
   end subroutine skyline_matvec
end module femcod_skyline
