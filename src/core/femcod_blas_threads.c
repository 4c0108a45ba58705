/* OpenBLAS's thread count, where the BLAS is OpenBLAS. Its LAPACK factorisations (dpotrf,
 * dpotri, dsysv) block their work by the number of threads, so their rounding, and so
 * femcod's answer, would follow OPENBLAS_NUM_THREADS (or OMP_NUM_THREADS, which OpenBLAS
 * reads when that is unset). femcod runs them on one thread (femcod_lapack's
 * one_thread_factorisation): the same bits on any number of threads. The symbols are
 * weak: with another BLAS they are absent and nothing is changed. */
extern void openblas_set_num_threads(int) __attribute__((weak));
extern int openblas_get_num_threads(void) __attribute__((weak));

/* Set OpenBLAS's threads to n; the number before, or -1 when the BLAS is not OpenBLAS. */
int femcod_blas_set_threads(int n)
{
    int before;
    if (!openblas_set_num_threads || !openblas_get_num_threads) return -1;
    before = openblas_get_num_threads();
    openblas_set_num_threads(n);
    return before;
}
