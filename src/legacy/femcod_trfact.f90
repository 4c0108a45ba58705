!> TRFACT: the active-column (skyline) solver of FEMCOD, K = U' D U with U unit upper
!> triangular ("triple factorisation", L D U with L = U'). Called twice as in
!> Appendix B: once to factorise in place, once to solve for a load vector.
!>
!> Storage as in femcod_skyline: column j holds rows j-h(j)..j, diagonal at iadr(j).
!> After factorisation the diagonal holds D and the off-diagonal entries hold U.
module femcod_trfact
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_lapack, only: dlacn2
   implicit none
   private
   public :: trfact, trfact_condition, TRFACT_FACTOR, TRFACT_SOLVE

   integer, parameter :: TRFACT_FACTOR = 1, TRFACT_SOLVE = 2

contains

   !> job = TRFACT_FACTOR: factorise `a` in place (a non-positive pivot, relative to
   !> the original diagonal, is a numerical error: the system must be positive definite).
   !> job = TRFACT_SOLVE: overwrite `b` with the solution of K x = b, `a` factorised.
   pure subroutine trfact(a, iadr, b, job, status, pivot_loss)
      real(dp), intent(inout) :: a(:)
      integer, intent(in) :: iadr(:)
      real(dp), intent(inout) :: b(:)
      integer, intent(in) :: job
      type(status_type), intent(inout) :: status
      !> With TRFACT_FACTOR: the largest ratio of a diagonal entry before elimination to
      !> its pivot after, a cheap estimate of the condition growth: about
      !> log10(pivot_loss) significant digits are lost to cancellation.
      real(dp), intent(out), optional :: pivot_loss
      integer :: n, j, i, top_j, top_i, k0, ij, len, ifirst, jfirst
      real(dp) :: g, diag0
      n = size(iadr)
      if (present(pivot_loss)) pivot_loss = 1
      select case (job)
      case (TRFACT_FACTOR)
         do j = 1, n
            top_j = top(j)
            diag0 = a(iadr(j))
            ! g(i) = a(i,j) - sum_k U(k,i) g(k): reduce column j.
            do i = top_j + 1, j - 1
               top_i = top(i)
               k0 = max(top_i, top_j)
               len = i - k0
               if (len > 0) then
                  ifirst = iadr(i) - (i - k0)
                  jfirst = iadr(j) - (j - k0)
                  ij = iadr(j) - (j - i)
                  a(ij) = a(ij) - dot_product(a(ifirst:ifirst + len - 1), a(jfirst:jfirst + len - 1))
               end if
            end do
            ! U(i,j) = g(i)/D(i); D(j) = a(j,j) - sum g(i) U(i,j).
            do i = top_j, j - 1
               ij = iadr(j) - (j - i)
               g = a(ij)
               a(ij) = g/a(iadr(i))
               a(iadr(j)) = a(iadr(j)) - g*a(ij)
            end do
            if (.not. a(iadr(j)) > epsilon(1.0_dp)*abs(diag0)) then
               call set_error(status, STATUS_NUMERICAL, "TRFACT: the stiffness matrix is not positive definite "// &
                  "(pivot lost all significant digits)")
               return
            end if
            if (present(pivot_loss)) pivot_loss = max(pivot_loss, abs(diag0)/a(iadr(j)))
         end do
      case (TRFACT_SOLVE)
         ! Forward: U' y = b.
         do j = 1, n
            top_j = top(j)
            len = j - top_j
            if (len > 0) b(j) = b(j) - dot_product(a(iadr(j) - len:iadr(j) - 1), b(top_j:j - 1))
         end do
         b = b/a(iadr)
         ! Backward: U x = y, column by column.
         do j = n, 2, -1
            top_j = top(j)
            len = j - top_j
            if (len > 0) b(top_j:j - 1) = b(top_j:j - 1) - a(iadr(j) - len:iadr(j) - 1)*b(j)
         end do
      end select
   contains
      pure integer function top(col)
         integer, intent(in) :: col
         if (col == 1) then
            top = 1
         else
            top = col - (iadr(col) - iadr(col - 1) - 1)
         end if
      end function top
   end subroutine trfact

   !> Estimate of the 1-norm condition number ||K||_1 ||K^-1||_1 of the symmetric
   !> skyline matrix: ||K||_1 from `original` (K before TRFACT_FACTOR), ||K^-1||_1 by
   !> LAPACK's estimator dlacn2 driving solves with the factor in `factored` (a few
   !> solves, each as cheap as one TRFACT_SOLVE). The relative error of a solve is then
   !> about eps times the estimate.
   function trfact_condition(factored, original, iadr) result(kappa)
      real(dp), intent(in) :: factored(:), original(:)
      integer, intent(in) :: iadr(:)
      real(dp) :: kappa
      real(dp), allocatable :: colsum(:), v(:), x(:), work(:)
      integer, allocatable :: isgn(:)
      real(dp) :: est
      integer :: n, j, i, top_j, kase, isave(3)
      type(status_type) :: ignore
      n = size(iadr)
      allocate(colsum(n), v(n), x(n), isgn(n))
      colsum = 0
      do j = 1, n
         top_j = 1
         if (j > 1) top_j = j - (iadr(j) - iadr(j - 1) - 1)
         do i = top_j, j
            colsum(j) = colsum(j) + abs(original(iadr(j) - (j - i)))
            if (i < j) colsum(i) = colsum(i) + abs(original(iadr(j) - (j - i)))
         end do
      end do
      est = 0
      kase = 0
      work = factored
      do
         call dlacn2(n, v, x, isgn, est, kase, isave)
         if (kase == 0) exit
         ! K is symmetric: K^-T x = K^-1 x.
         call trfact(work, iadr, x, TRFACT_SOLVE, ignore)
      end do
      kappa = maxval(colsum)*est
   end function trfact_condition
end module femcod_trfact
