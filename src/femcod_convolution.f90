!> Love-kernel convolution on the whole NP x NP grid by zero-padded (2NP)^2 real FFTs
!> (FFTW, plans made once): (I * F)(p) = sum_k I(p - k) F(k), exact for the non-periodic
!> half-space because the padding keeps every image out of the grid.
!>
!> The 2-D transform is done as two passes of 1-D transforms so that the padding costs
!> nothing it need not: the forward column pass transforms only the NP columns that hold
!> data (the other NP are zero), the backward column pass only the NP columns that are
!> read back. Both row passes are full. That is 3/4 of the work of a full 2-D r2c/c2r
!> pair. The kernel is even in both offsets, so its spectrum is real and the product is a
!> real scaling of the complex spectrum.
!>
!> `convolution_apply_single` does the same in float32 (FFTW's single-precision library,
!> on the same memory): about half the time, relative error ~1e-7 of the result. The
!> fixed-load solver uses it for its early iterations only.
!>
!> FFTW runs with as many threads as OpenMP allows (OMP_NUM_THREADS, default all cores).
module femcod_convolution
   use, intrinsic :: iso_c_binding, only: c_ptr, c_double, c_float, c_double_complex, c_float_complex, c_int, &
      c_size_t, c_f_pointer
   use femcod_kinds, only: dp
   use femcod_fftw, only: fftw_plan_many_dft_r2c, fftw_plan_many_dft_c2r, fftw_plan_many_dft, &
      fftw_execute_dft_r2c, fftw_execute_dft_c2r, fftw_execute_dft, &
      fftwf_plan_many_dft_r2c, fftwf_plan_many_dft_c2r, fftwf_plan_many_dft, &
      fftwf_execute_dft_r2c, fftwf_execute_dft_c2r, fftwf_execute_dft, &
      fftw_destroy_plan, fftwf_destroy_plan, fftw_alloc_real, fftw_alloc_complex, fftw_free, &
      fftw_init_threads, fftwf_init_threads, fftw_plan_with_nthreads, fftwf_plan_with_nthreads, &
      FFTW_ESTIMATE, FFTW_MEASURE, FFTW_FORWARD, FFTW_BACKWARD
   !$ use omp_lib, only: omp_get_max_threads
   implicit none
   private
   public :: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, convolution_free, &
      inverse_kernel_taps, start_fft_threads

   integer, parameter :: sp = kind(1.0)

   !> One set of plans for one precision.
   type :: plan_set
      type(c_ptr) :: columns_forward, rows_forward, rows_backward, columns_backward
   end type plan_set

   !> Plans, the transformed kernel and work arrays for one grid size.
   type :: love_convolution
      !> Grid size NP, padded size M = 2 NP, complex rows MH = M/2 + 1.
      integer :: np = 0, m = 0, mh = 0
      logical :: has_single = .false.
      type(plan_set) :: double, single
      type(c_ptr) :: real_mem, complex_mem
      !> Column-pass data (M x NP) and the half spectrum (MH x M), double and float32 views
      !> of the same memory.
      real(c_double), pointer :: work(:, :) => null()
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
      real(c_float), pointer :: work32(:, :) => null()
      complex(c_float_complex), pointer :: spectrum32(:, :) => null()
      !> Real kernel spectrum divided by M^2 (MH x M), and its float32 copy.
      real(dp), allocatable :: kernel(:, :)
      real(sp), allocatable :: kernel32(:, :)
   end type love_convolution

   logical, save :: threads_ready = .false.

contains

   !> Plan the transforms and transform the kernel table(0:np-1, 0:np-1). With
   !> `single` true the float32 plans are made as well. With `measure` true FFTW times
   !> candidate plans (FFTW_MEASURE: seconds of planning at NP >= 1024, faster transforms;
   !> plans in FFTW's wisdom, which the caller may import beforehand, are reused at once);
   !> otherwise it picks them by estimate.
   subroutine convolution_setup(conv, table, single, measure)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in) :: table(0:, 0:)
      logical, intent(in), optional :: single, measure
      integer :: np, m, mh, p, q, ip, iq, nthreads
      integer(c_int) :: flags
      np = size(table, 1)
      m = 2*np
      mh = m/2 + 1
      conv%np = np
      conv%m = m
      conv%mh = mh
      nthreads = 1
      !$ nthreads = omp_get_max_threads()
      call start_fft_threads()
      flags = FFTW_ESTIMATE
      if (present(measure)) then
         if (measure) flags = FFTW_MEASURE
      end if
      call fftw_plan_with_nthreads(int(nthreads, c_int))
      call fftwf_plan_with_nthreads(int(nthreads, c_int))
      conv%real_mem = fftw_alloc_real(int(m, c_size_t)*int(np, c_size_t))
      conv%complex_mem = fftw_alloc_complex(int(mh, c_size_t)*int(m, c_size_t))
      call c_f_pointer(conv%real_mem, conv%work, [m, np])
      call c_f_pointer(conv%complex_mem, conv%spectrum, [mh, m])
      call c_f_pointer(conv%real_mem, conv%work32, [m, np])
      call c_f_pointer(conv%complex_mem, conv%spectrum32, [mh, m])
      associate(d => conv%double)
         d%columns_forward = fftw_plan_many_dft_r2c(1_c_int, [int(m, c_int)], int(np, c_int), &
            conv%work, [int(m, c_int)], 1_c_int, int(m, c_int), &
            conv%spectrum, [int(mh, c_int)], 1_c_int, int(mh, c_int), flags)
         d%rows_forward = fftw_plan_many_dft(1_c_int, [int(m, c_int)], int(mh, c_int), &
            conv%spectrum, [int(m, c_int)], int(mh, c_int), 1_c_int, &
            conv%spectrum, [int(m, c_int)], int(mh, c_int), 1_c_int, FFTW_FORWARD, flags)
         d%rows_backward = fftw_plan_many_dft(1_c_int, [int(m, c_int)], int(mh, c_int), &
            conv%spectrum, [int(m, c_int)], int(mh, c_int), 1_c_int, &
            conv%spectrum, [int(m, c_int)], int(mh, c_int), 1_c_int, FFTW_BACKWARD, flags)
         d%columns_backward = fftw_plan_many_dft_c2r(1_c_int, [int(m, c_int)], int(np, c_int), &
            conv%spectrum, [int(mh, c_int)], 1_c_int, int(mh, c_int), &
            conv%work, [int(m, c_int)], 1_c_int, int(m, c_int), flags)
      end associate
      conv%has_single = .false.
      if (present(single)) conv%has_single = single
      if (conv%has_single) then
         associate(s => conv%single)
            s%columns_forward = fftwf_plan_many_dft_r2c(1_c_int, [int(m, c_int)], int(np, c_int), &
               conv%work32, [int(m, c_int)], 1_c_int, int(m, c_int), &
               conv%spectrum32, [int(mh, c_int)], 1_c_int, int(mh, c_int), flags)
            s%rows_forward = fftwf_plan_many_dft(1_c_int, [int(m, c_int)], int(mh, c_int), &
               conv%spectrum32, [int(m, c_int)], int(mh, c_int), 1_c_int, &
               conv%spectrum32, [int(m, c_int)], int(mh, c_int), 1_c_int, FFTW_FORWARD, flags)
            s%rows_backward = fftwf_plan_many_dft(1_c_int, [int(m, c_int)], int(mh, c_int), &
               conv%spectrum32, [int(m, c_int)], int(mh, c_int), 1_c_int, &
               conv%spectrum32, [int(m, c_int)], int(mh, c_int), 1_c_int, FFTW_BACKWARD, flags)
            s%columns_backward = fftwf_plan_many_dft_c2r(1_c_int, [int(m, c_int)], int(np, c_int), &
               conv%spectrum32, [int(mh, c_int)], 1_c_int, int(mh, c_int), &
               conv%work32, [int(m, c_int)], 1_c_int, int(m, c_int), flags)
         end associate
      end if
      ! Kernel on the padded grid: offsets 0..np-1 and -(np-1)..-1 (wrapped); the
      ! middle row/column (offset np) is never reached by a pair of grid pixels. Only
      ! the first NP columns (offsets q = 0..np-1) fit the column-pass buffer, so the
      ! kernel's spectrum is built from its even symmetry in q: the column pass of
      ! column -q equals that of column q.
      do q = 0, np - 1
         do p = -(np - 1), np - 1
            ip = modulo(p, m) + 1
            conv%work(ip, q + 1) = table(abs(p), q)
         end do
         conv%work(np + 1, q + 1) = 0
      end do
      call fftw_execute_dft_r2c(conv%double%columns_forward, conv%work, conv%spectrum)
      do q = 1, np - 1
         iq = m - q + 1
         conv%spectrum(:, iq) = conv%spectrum(:, q + 1)
      end do
      conv%spectrum(:, np + 1) = 0
      call fftw_execute_dft(conv%double%rows_forward, conv%spectrum, conv%spectrum)
      ! Even kernel: the spectrum is real (the imaginary part is round-off).
      conv%kernel = real(conv%spectrum, dp)/real(m, dp)**2
      if (conv%has_single) conv%kernel32 = real(conv%kernel, sp)
   end subroutine convolution_setup

   !> Initialise FFTW's threads once; before any other FFTW call (wisdom included).
   subroutine start_fft_threads()
      integer(c_int) :: ios
      if (threads_ready) return
      ios = fftw_init_threads()
      ios = fftwf_init_threads()
      threads_ready = .true.
   end subroutine start_fft_threads

   !> result(i, j) = factor * sum_{k,l} I(i-k, j-l) field(k, l) over the NP x NP grid.
   subroutine convolution_apply(conv, field, result, factor)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in) :: field(:, :)
      real(dp), intent(out) :: result(:, :)
      !> Multiplies the result (default 1): a compliance, folded into the last copy.
      real(dp), intent(in), optional :: factor
      real(dp) :: f
      integer :: np, j
      f = 1
      if (present(factor)) f = factor
      np = conv%np
      !$omp parallel do
      do j = 1, np
         conv%work(1:np, j) = field(:, j)
         conv%work(np + 1:, j) = 0
      end do
      call fftw_execute_dft_r2c(conv%double%columns_forward, conv%work, conv%spectrum)
      !$omp parallel do
      do j = np + 1, conv%m
         conv%spectrum(:, j) = 0
      end do
      call fftw_execute_dft(conv%double%rows_forward, conv%spectrum, conv%spectrum)
      !$omp parallel do
      do j = 1, conv%m
         conv%spectrum(:, j) = conv%spectrum(:, j)*conv%kernel(:, j)
      end do
      call fftw_execute_dft(conv%double%rows_backward, conv%spectrum, conv%spectrum)
      call fftw_execute_dft_c2r(conv%double%columns_backward, conv%spectrum, conv%work)
      !$omp parallel do
      do j = 1, np
         result(:, j) = f*conv%work(1:np, j)
      end do
   end subroutine convolution_apply

   !> As convolution_apply, with float32 transforms (needs setup with single = .true.).
   subroutine convolution_apply_single(conv, field, result, factor)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in) :: field(:, :)
      real(dp), intent(out) :: result(:, :)
      !> Multiplies the result (default 1): a compliance, folded into the last copy.
      real(dp), intent(in), optional :: factor
      real(dp) :: f
      integer :: np, j
      f = 1
      if (present(factor)) f = factor
      np = conv%np
      !$omp parallel do
      do j = 1, np
         conv%work32(1:np, j) = real(field(:, j), sp)
         conv%work32(np + 1:, j) = 0
      end do
      call fftwf_execute_dft_r2c(conv%single%columns_forward, conv%work32, conv%spectrum32)
      !$omp parallel do
      do j = np + 1, conv%m
         conv%spectrum32(:, j) = 0
      end do
      call fftwf_execute_dft(conv%single%rows_forward, conv%spectrum32, conv%spectrum32)
      !$omp parallel do
      do j = 1, conv%m
         conv%spectrum32(:, j) = conv%spectrum32(:, j)*conv%kernel32(:, j)
      end do
      call fftwf_execute_dft(conv%single%rows_backward, conv%spectrum32, conv%spectrum32)
      call fftwf_execute_dft_c2r(conv%single%columns_backward, conv%spectrum32, conv%work32)
      !$omp parallel do
      do j = 1, np
         result(:, j) = f*real(conv%work32(1:np, j), dp)
      end do
   end subroutine convolution_apply_single

   !> The central coefficients of the inverse of the convolution on the padded periodic
   !> grid: taps(a, b), a, b = 0..2, at offsets (+-a, +-b) (dimensionless, for the table's
   !> units; a discrete form of the |q| operator, E* |q| / 2 in the continuum). `ok` is
   !> false when the kernel spectrum is not positive, so that it has no inverse.
   subroutine inverse_kernel_taps(conv, taps, ok)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(out) :: taps(0:2, 0:2)
      logical, intent(out) :: ok
      integer :: j
      taps = 0
      ok = minval(conv%kernel) > 0 .and. conv%np >= 3
      if (.not. ok) return
      do j = 1, conv%m
         conv%spectrum(:, j) = 1/conv%kernel(:, j)
      end do
      call fftw_execute_dft(conv%double%rows_backward, conv%spectrum, conv%spectrum)
      call fftw_execute_dft_c2r(conv%double%columns_backward, conv%spectrum, conv%work)
      taps = conv%work(1:3, 1:3)/real(conv%m, dp)**4
   end subroutine inverse_kernel_taps

   subroutine convolution_free(conv)
      type(love_convolution), intent(inout) :: conv
      if (conv%m == 0) return
      call fftw_destroy_plan(conv%double%columns_forward)
      call fftw_destroy_plan(conv%double%rows_forward)
      call fftw_destroy_plan(conv%double%rows_backward)
      call fftw_destroy_plan(conv%double%columns_backward)
      if (conv%has_single) then
         call fftwf_destroy_plan(conv%single%columns_forward)
         call fftwf_destroy_plan(conv%single%rows_forward)
         call fftwf_destroy_plan(conv%single%rows_backward)
         call fftwf_destroy_plan(conv%single%columns_backward)
      end if
      call fftw_free(conv%real_mem)
      call fftw_free(conv%complex_mem)
      nullify(conv%work, conv%spectrum, conv%work32, conv%spectrum32)
      if (allocated(conv%kernel)) deallocate(conv%kernel)
      if (allocated(conv%kernel32)) deallocate(conv%kernel32)
      conv%m = 0
      conv%has_single = .false.
   end subroutine convolution_free
end module femcod_convolution
