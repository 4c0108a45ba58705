!> TRFACT: the active-column (skyline) solver of FEMCOD, K = U' D U with U unit upper
!> triangular ("triple factorisation", L D U with L = U'). Called twice as in
!> Appendix B: once to factorise in place, once to solve for a load vector.
!>
!> Storage as in femcod_skyline: column j holds rows j-h(j)..j, diagonal at iadr(j).
!> After factorisation the diagonal holds D and the off-diagonal entries hold U.
module femcod_trfact
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
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
   !> Hager's and Higham's estimator (LAPACK's dlacn2, Higham, ACM TOMS 14, 1988, 381-396,
   !> Algorithm 4.1) driving solves with the factor in `factored`: at most 5 steps and the
   !> alternative vector, each a solve as cheap as one TRFACT_SOLVE; K symmetric, so that
   !> K^-T = K^-1. Written here, in plain loops, rather than through dlacn2, whose sums are
   !> OpenBLAS's (dasum, idamax): through them the estimate followed OpenBLAS's thread
   !> count in its last digits (input/sphere_d05.deck's /run/trfact_condition differed
   !> under OPENBLAS_NUM_THREADS=1 and 2). The relative error of a solve is about eps
   !> times the estimate.
   function trfact_condition(factored, original, iadr) result(kappa)
      real(dp), intent(in) :: factored(:), original(:)
      integer, intent(in) :: iadr(:)
      real(dp) :: kappa
      integer, parameter :: MAX_STEPS = 5
      real(dp), allocatable :: colsum(:), x(:), xi(:), work(:)
      real(dp) :: est, previous
      integer :: n, j, i, top_j, jlast, step
      type(status_type) :: ignore
      n = size(iadr)
      allocate(colsum(n), x(n), xi(n))
      colsum = 0
      do j = 1, n
         top_j = 1
         if (j > 1) top_j = j - (iadr(j) - iadr(j - 1) - 1)
         do i = top_j, j
            colsum(j) = colsum(j) + abs(original(iadr(j) - (j - i)))
            if (i < j) colsum(i) = colsum(i) + abs(original(iadr(j) - (j - i)))
         end do
      end do
      work = factored
      ! ||K^-1 x||_1 of x = (1/n, ..., 1/n), then steps from the unit vector of the largest
      ! |K^-1 sign(K^-1 x)| while the estimate grows and the signs change.
      x = 1.0_dp/n
      call solve(x)
      est = sum(abs(x))
      if (n > 1) then
         xi = signs(x)
         x = xi
         call solve(x)
         j = largest(x)
         do step = 2, MAX_STEPS
            x = 0
            x(j) = 1
            call solve(x)
            previous = est
            est = sum(abs(x))
            ! A repeated sign vector (converged) or no growth (cycling): as dlacn2, the
            ! last estimate stands.
            if (all(signs(x) == xi) .or. est <= previous) exit
            xi = signs(x)
            x = xi
            call solve(x)
            jlast = j
            j = largest(x)
            if (x(jlast) == abs(x(j))) exit
         end do
         ! The alternative vector, against cancellation: 2 ||K^-1 b||_1/(3n) of
         ! b(i) = (-1)^(i+1) (1 + (i-1)/(n-1)).
         x = [(merge(1.0_dp, -1.0_dp, mod(i, 2) == 1)*(1 + real(i - 1, dp)/(n - 1)), i = 1, n)]
         call solve(x)
         est = max(est, 2*(sum(abs(x))/real(3*n, dp)))
      end if
      kappa = maxval(colsum)*est
   contains
      subroutine solve(b)
         real(dp), intent(inout) :: b(:)
         call trfact(work, iadr, b, TRFACT_SOLVE, ignore)
      end subroutine solve
      !> +1 where v(i) >= 0 (-0 too), -1 elsewhere.
      pure function signs(v)
         real(dp), intent(in) :: v(:)
         real(dp) :: signs(size(v))
         signs = merge(1.0_dp, -1.0_dp, v >= 0)
      end function signs
      !> The first index of the largest |v(i)| (BLAS's idamax).
      pure integer function largest(v)
         real(dp), intent(in) :: v(:)
         largest = maxloc(abs(v), dim=1)
      end function largest
   end function trfact_condition
end module femcod_trfact
