!> BOUSSINESQ of Appendix B: the super-element of the half-space under the contact
!> pixels (thesis section 4.2.1), built from the Love kernel of model/femcod_love: its
!> flexibility gathered from the influence table, inverted by LAPACK, and bordered by
!> the handle node of eq. 4.6.
module femcod_boussinesq
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use, intrinsic :: iso_c_binding, only: c_int
   use femcod_lapack, only: dpotrf, dpotri, blas_set_threads
   implicit none
   private
   public :: boussinesq_flexibility, boussinesq_inverse, boussinesq_element

contains

   !> Dimensionless flexibility of the pixels (rows(k), cols(k)): F(k,l) = I(offset).
   pure function boussinesq_flexibility(rows, cols, table) result(flex)
      integer, intent(in) :: rows(:), cols(:)
      real(dp), intent(in) :: table(0:, 0:)
      real(dp) :: flex(size(rows), size(rows))
      integer :: k, l
      do l = 1, size(rows)
         do k = 1, l
            flex(k, l) = table(abs(rows(k) - rows(l)), abs(cols(k) - cols(l)))
            flex(l, k) = flex(k, l)
         end do
      end do
   end function boussinesq_flexibility

   !> Inverse of the dimensionless flexibility (symmetric positive definite): LAPACK
   !> Cholesky factorisation and inversion, full matrix returned.
   subroutine boussinesq_inverse(flex, stiff, status)
      real(dp), intent(in) :: flex(:, :)
      real(dp), intent(out) :: stiff(:, :)
      type(status_type), intent(inout) :: status
      integer :: n, info, k
      integer(c_int) :: before
      n = size(flex, 1)
      stiff = flex
      ! On one OpenBLAS thread: the same bits whatever the thread count.
      before = blas_set_threads(1_c_int)
      call dpotrf("U", n, stiff, n, info)
      if (info == 0) call dpotri("U", n, stiff, n, info)
      if (before > 0) before = blas_set_threads(before)
      if (info /= 0) then
         call set_error(status, STATUS_NUMERICAL, "BOUSSINESQ: the flexibility matrix is not positive definite")
         return
      end if
      do k = 1, n - 1
         stiff(k + 1:n, k) = stiff(k, k + 1:n)
      end do
   end subroutine boussinesq_inverse

   !> BOUSSINESQ element stiffness (nN/nm) of n substrate nodes plus the handle node
   !> (last row and column), from the inverse dimensionless flexibility `kinv` and the
   !> surface compliance factor c: K* = kinv / c, and by eq. 4.6
   !>   k(i, n+1) = -sum_j k(i, j),   k(n+1, n+1) = sum_ij k(i, j),
   !> so that a rigid-body motion of all nodes produces no force.
   pure subroutine boussinesq_element(kinv, compliance, element)
      real(dp), intent(in) :: kinv(:, :), compliance
      real(dp), intent(out) :: element(:, :)
      integer :: n
      n = size(kinv, 1)
      element(1:n, 1:n) = kinv/compliance
      element(1:n, n + 1) = -sum(element(1:n, 1:n), dim=2)
      element(n + 1, 1:n) = element(1:n, n + 1)
      element(n + 1, n + 1) = -sum(element(1:n, n + 1))
   end subroutine boussinesq_element
end module femcod_boussinesq
