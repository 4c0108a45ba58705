!> Explicit interfaces to the LAPACK and BLAS routines femcod calls
!> (implicit-external is off in fpm.toml).
module femcod_lapack
   use, intrinsic :: iso_c_binding, only: c_int
   use femcod_kinds, only: dp
   implicit none
   private
   public :: dpotrf, dpotri, dsysv, dgesv, ddot, dgemv, dsymv, dtpsv, dpptrf, dtrsv, dlacn2, dtrsm, dsyrk, dgemm
   public :: blas_set_threads

   interface
      !> OpenBLAS's threads set to n; the number before, -1 with another BLAS
      !> (core/femcod_blas_threads.c). Its factorisations block their work by the
      !> threads: run on one, their bits do not depend on the thread count.
      integer(c_int) function blas_set_threads(n) bind(C, name="femcod_blas_set_threads")
         import :: c_int
         integer(c_int), value :: n
      end function blas_set_threads
      pure subroutine dpotrf(uplo, n, a, lda, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(dp), intent(inout) :: a(lda, *)
         integer, intent(out) :: info
      end subroutine dpotrf
      pure subroutine dpotri(uplo, n, a, lda, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(dp), intent(inout) :: a(lda, *)
         integer, intent(out) :: info
      end subroutine dpotri
      pure subroutine dsysv(uplo, n, nrhs, a, lda, ipiv, b, ldb, work, lwork, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, nrhs, lda, ldb, lwork
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
         real(dp), intent(inout) :: work(*)
      end subroutine dsysv
      pure subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: dp
         integer, intent(in) :: n, nrhs, lda, ldb
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgesv
      pure real(dp) function ddot(n, x, incx, y, incy)
         import :: dp
         integer, intent(in) :: n, incx, incy
         real(dp), intent(in) :: x(*), y(*)
      end function ddot
      !> C = alpha A A^T + beta C (uplo's triangle of C), A n x k.
      pure subroutine dsyrk(uplo, trans, n, k, alpha, a, lda, beta, c, ldc)
         import :: dp
         character(len=1), intent(in) :: uplo, trans
         integer, intent(in) :: n, k, lda, ldc
         real(dp), intent(in) :: alpha, beta, a(lda, *)
         real(dp), intent(inout) :: c(ldc, *)
      end subroutine dsyrk
      pure subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
         import :: dp
         character(len=1), intent(in) :: transa, transb
         integer, intent(in) :: m, n, k, lda, ldb, ldc
         real(dp), intent(in) :: alpha, beta, a(lda, *), b(ldb, *)
         real(dp), intent(inout) :: c(ldc, *)
      end subroutine dgemm
      pure subroutine dgemv(trans, m, n, alpha, a, lda, x, incx, beta, y, incy)
         import :: dp
         character(len=1), intent(in) :: trans
         integer, intent(in) :: m, n, lda, incx, incy
         real(dp), intent(in) :: alpha, beta, a(lda, *), x(*)
         real(dp), intent(inout) :: y(*)
      end subroutine dgemv
      pure subroutine dsymv(uplo, n, alpha, a, lda, x, incx, beta, y, incy)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda, incx, incy
         real(dp), intent(in) :: alpha, beta, a(lda, *), x(*)
         real(dp), intent(inout) :: y(*)
      end subroutine dsymv
      pure subroutine dtpsv(uplo, trans, diag, n, ap, x, incx)
         import :: dp
         character(len=1), intent(in) :: uplo, trans, diag
         integer, intent(in) :: n, incx
         real(dp), intent(in) :: ap(*)
         real(dp), intent(inout) :: x(*)
      end subroutine dtpsv
      pure subroutine dtrsv(uplo, trans, diag, n, a, lda, x, incx)
         import :: dp
         character(len=1), intent(in) :: uplo, trans, diag
         integer, intent(in) :: n, lda, incx
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: x(*)
      end subroutine dtrsv
      pure subroutine dtrsm(side, uplo, transa, diag, m, n, alpha, a, lda, b, ldb)
         import :: dp
         character(len=1), intent(in) :: side, uplo, transa, diag
         integer, intent(in) :: m, n, lda, ldb
         real(dp), intent(in) :: alpha, a(lda, *)
         real(dp), intent(inout) :: b(ldb, *)
      end subroutine dtrsm
      pure subroutine dpptrf(uplo, n, ap, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n
         real(dp), intent(inout) :: ap(*)
         integer, intent(out) :: info
      end subroutine dpptrf
      !> LAPACK's 1-norm estimator (Higham's reverse-communication form of Hager's method).
      subroutine dlacn2(n, v, x, isgn, est, kase, isave)
         import :: dp
         integer, intent(in) :: n
         real(dp), intent(inout) :: v(*), x(*), est
         integer, intent(inout) :: isgn(*), kase, isave(3)
      end subroutine dlacn2
   end interface
end module femcod_lapack
