!> Love-kernel convolution on the whole NP x NP grid by zero-padded (2NP)^2 real FFTs
!> (FFTW, plans made once): (I * F)(p) = sum_k I(p - k) F(k), exact for the non-periodic
!> half-space because the padding keeps every image out of the grid.
!>
!> For a periodic surface (`periodic` at set-up, `--boundary periodic`) the same passes
!> run on the unpadded NP^2 grid with a periodic table (femcod_love_periodic): the
!> cyclic convolution sum_k K((p - k) mod NP) F(k), with transforms of half the length
!> per dimension, a quarter of the data, and no padding to fill or crop.
!>
!> The 2-D transform is done in three passes of 1-D transforms so that the padding costs
!> nothing it need not, and each pass works through the grid in blocks of a few lines
!> that stay in cache (one block per OpenMP thread at a time, FFTW's single-threaded
!> plans executed on each thread's own buffers):
!>   1. columns: each of the NP data columns, zero-padded to M = 2 NP, by a real r2c
!>      transform into the half spectrum (MH = NP + 1 rows; the other NP columns are zero
!>      and are never stored);
!>   2. rows: a block of spectrum rows is gathered into contiguous lines of length M (the
!>      zero half filled in), transformed forward, multiplied by the kernel's spectrum,
!>      transformed back, and only its first NP entries written back (only those columns
!>      are read back);
!>   3. columns: c2r of the NP columns read back, cropped to the grid.
!> That is 3/4 of the work of a full 2-D r2c/c2r pair, and the spectrum held is MH x NP
!> instead of MH x M. The kernel is even in both offsets, so its spectrum is real and
!> even, and is kept for k2 = 0..NP only (the other half is its mirror image).
!>
!> `convolution_apply_single` does the same in float32 (FFTW's single-precision library,
!> on the same memory): about half the time, relative error ~1e-7 of the result. The
!> fixed-load solver uses it for its early iterations and its search directions.
!>
!> The passes run on as many threads as OpenMP allows (OMP_NUM_THREADS, default all
!> cores) when the convolution is set up.
!>
!> Every FFTW plan of the serial library is made here: the convolution's, the gap-
!> variable iteration's transform grid (gap_transform), and the one-off transforms of the
!> periodic table (inverse_half_spectrum), the self-affine generator
!> (inverse_complex_transform), the profiles' spectra (line_transform) and the bare pair
!> the benchmarks measure a convolution against (transform_pair). FFTW-MPI's
!> plans are femcod-mpi's (mpi/src).
module femcod_convolution
   use, intrinsic :: iso_c_binding, only: c_ptr, c_double, c_float, c_double_complex, c_float_complex, c_int, &
      c_size_t, c_f_pointer
   use femcod_kinds, only: dp, sp
   use femcod_fftw, only: fftw_plan_many_dft_r2c, fftw_plan_many_dft_c2r, fftw_plan_many_dft, &
      fftw_execute_dft_r2c, fftw_execute_dft_c2r, fftw_execute_dft, &
      fftwf_plan_many_dft_r2c, fftwf_plan_many_dft_c2r, fftwf_plan_many_dft, &
      fftwf_execute_dft_r2c, fftwf_execute_dft_c2r, fftwf_execute_dft, &
      fftw_destroy_plan, fftwf_destroy_plan, fftw_alloc_real, fftw_alloc_complex, fftw_free, &
      FFTW_ESTIMATE, FFTW_MEASURE, FFTW_FORWARD, FFTW_BACKWARD, fftw_plan_dft_r2c_2d, fftw_plan_dft_c2r_2d, &
      fftw_init_threads, fftw_plan_with_nthreads, fftw_plan_dft_2d, fftw_plan_dft_r2c_1d
   !$ use omp_lib, only: omp_get_max_threads, omp_get_thread_num
   implicit none
   private
   public :: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, convolution_free, &
      inverse_kernel_taps, inverse_tap_sums, mirror_weights
   public :: gap_transform, gap_transform_setup, gap_transform_apply, gap_transform_free, SPECTRUM_COMPLIANCE, &
      SPECTRUM_STIFFNESS
   public :: inverse_half_spectrum, inverse_complex_transform, forward_complex_transform, line_transform, line_transform_setup, &
      line_transform_apply, line_transform_free
   public :: shear_transform, shear_transform_setup, shear_transform_setup_periodic, shear_transform_apply, &
      shear_transform_free
   public :: transform_pair, transform_pair_setup, transform_pair_apply, transform_pair_free

   !> Which operator gap_transform_apply applies: the compliance C = c (I * .) + s or the
   !> stiffness K = C^-1.
   integer, parameter :: SPECTRUM_COMPLIANCE = 1, SPECTRUM_STIFFNESS = 2

   !> Lines per block in every pass: 8 lines of M = 8192 are 0.5 MB of float32 complex, in
   !> L2 cache; 4 and 16 were slower at NP = 4096 (doc/performance.md, the convolution).
   integer, parameter :: lines_per_block = 8

   !> One set of plans for one precision, each for one block of `lines_per_block` lines of
   !> length M: r2c and c2r down contiguous columns, forward and backward complex along
   !> contiguous lines (in place). Single-threaded; run on each thread's own buffers.
   type :: plan_set
      type(c_ptr) :: columns_forward, columns_backward, rows_forward, rows_backward
   end type plan_set

   !> Plans, the transformed kernel, the half spectrum and the threads' buffers for one
   !> grid size.
   type :: love_convolution
      !> Grid size NP, transform length M (2 NP padded, NP periodic), rows of the half
      !> spectrum MH = M/2 + 1, lines per block, threads (buffers) the passes run on.
      integer :: np = 0, m = 0, mh = 0, block = 0, threads = 0
      logical :: has_single = .false.
      !> Cyclic convolution of a periodic table on the unpadded grid.
      logical :: periodic = .false.
      type(plan_set) :: double, single
      !> The half spectrum of the NP data columns (MH x NP), in double or in float32.
      type(c_ptr) :: spectrum_mem
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
      complex(c_float_complex), pointer :: spectrum32(:, :) => null()
      !> Per thread: a real block (M x block) and a complex block (M x block).
      type(c_ptr), allocatable :: real_mem(:), complex_mem(:)
      !> Real kernel spectrum divided by M^2, transposed: kernel(k2, k1), k2 = 0..M/2,
      !> k1 = 1..MH (rounded to float32 where a float32 convolution uses it: no copy).
      real(dp), allocatable :: kernel(:, :)
   end type love_convolution

   !> The whole transform grid (M = 2 NP on the free half-space, NP on a periodic cell) as
   !> the gap-variable iteration (solvers/femcod_gap_cg) needs it: its unknowns live on all
   !> M^2 points (on the padding too), and it applies both C and K = C^-1, each diagonal in
   !> Fourier space. FFTW's threaded 2-D plans (OpenMP's threads) on one field and one
   !> spectrum; both spectra divided by M^2 for FFTW's unnormalised transforms, and on a
   !> periodic cell 0 at zero frequency (the mean gap is a constraint there).
   type :: gap_transform
      integer :: np = 0, m = 0
      logical :: periodic = .false.
      real(dp), allocatable :: compliance(:, :), stiffness(:, :)
      type(c_ptr) :: forward, backward, real_mem, complex_mem
      real(c_double), pointer :: field(:, :) => null()
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
   end type gap_transform

   !> The tangential (Cerruti) operator of the free half-space on the zero-padded grid
   !> (M = 2 NP): tangential forces (t_x, t_y) on the NP x NP grid in, the displacements
   !> u_x = xx * t_x + xy * t_y, u_y = xy * t_x + yy * t_y out (* the convolution over the
   !> grid). xx and yy are even in both offsets and xy odd in both, so all three spectra
   !> are real. FFTW's threaded 2-D plans, as gap_transform's.
   type :: shear_transform
      integer :: np = 0, m = 0
      !> The three spectra divided by M^2 (M/2 + 1 x M).
      real(dp), allocatable :: xx(:, :), yy(:, :), xy(:, :)
      !> The largest eigenvalue of the 2 x 2 spectrum over the frequencies (nm/nN): a
      !> bound on the operator's largest eigenvalue on the grid (a step for its solver).
      real(dp) :: largest = 0
      type(c_ptr) :: forward, backward, real_mem, complex_mem
      real(c_double), pointer :: field(:, :) => null()
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
      complex(dp), allocatable :: along_x(:, :)
   end type shear_transform

   !> A bare pair of transforms, the yardstick of a convolution's speed (femcod bench): one
   !> M x M real field to its half spectrum and back (FFTW's threaded 2-D r2c and c2r, on
   !> OpenMP's threads), with nothing between them.
   type :: transform_pair
      integer :: m = 0
      type(c_ptr) :: forward, backward, real_mem, complex_mem
      real(c_double), pointer :: field(:, :) => null()
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
   end type transform_pair

   !> Real-to-complex transforms of lines of one length (the profiles of femcod_summits):
   !> one plan, made on the caller's line and spectrum and executed on them.
   type :: line_transform
      type(c_ptr) :: plan
      logical :: made = .false.
   end type line_transform

contains

   !> Plan the transforms and transform the kernel table(0:np-1, 0:np-1). With
   !> `single` true the float32 plans are made as well. With `measure` true FFTW times
   !> candidate plans (FFTW_MEASURE: about a second at NP = 4096, faster transforms;
   !> plans in FFTW's wisdom, which the caller may import beforehand, are reused at once);
   !> otherwise it picks them by estimate. With `periodic` true the table is a periodic
   !> one (table(p, q) = table(NP - p, q), femcod_love_periodic) and the convolution
   !> cyclic, without padding.
   subroutine convolution_setup(conv, table, single, measure, periodic)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in) :: table(0:, 0:)
      logical, intent(in), optional :: single, measure, periodic
      integer :: np, m, mh, b, t, p, q, j, jb, j0, nb, thread, kh
      integer(c_int) :: flags
      real(c_double), pointer :: lines(:, :)
      complex(c_double_complex), pointer :: half(:, :)
      np = size(table, 1)
      conv%periodic = .false.
      if (present(periodic)) conv%periodic = periodic
      m = merge(np, 2*np, conv%periodic)
      mh = m/2 + 1
      kh = m/2
      b = min(lines_per_block, np)
      conv%np = np
      conv%m = m
      conv%mh = mh
      conv%block = b
      conv%threads = 1
      !$ conv%threads = omp_get_max_threads()
      flags = FFTW_ESTIMATE
      if (present(measure)) then
         if (measure) flags = FFTW_MEASURE
      end if
      conv%has_single = .false.
      if (present(single)) conv%has_single = single
      conv%spectrum_mem = fftw_alloc_complex(int(mh, c_size_t)*int(np, c_size_t))
      call c_f_pointer(conv%spectrum_mem, conv%spectrum, [mh, np])
      call c_f_pointer(conv%spectrum_mem, conv%spectrum32, [mh, np])
      allocate(conv%real_mem(0:conv%threads - 1), conv%complex_mem(0:conv%threads - 1))
      do t = 0, conv%threads - 1
         conv%real_mem(t) = fftw_alloc_real(int(m, c_size_t)*int(b, c_size_t))
         conv%complex_mem(t) = fftw_alloc_complex(int(m, c_size_t)*int(b, c_size_t))
      end do
      call make_plans_double(conv, flags)
      if (conv%has_single) call make_plans_single(conv, flags)
      ! Kernel on the padded grid: offsets 0..np-1 and -(np-1)..-1 (wrapped); the
      ! middle line (offset np) is never reached by a pair of grid pixels. Columns
      ! q = 0..np-1 go through the column pass into the half spectrum; the row pass fills
      ! columns q = np+1..m-1 from their mirror images m-q (the kernel is even in q).
      ! Periodic: the table is the whole cell, offsets 0..np-1 once, nothing mirrored.
      !$omp parallel num_threads(conv%threads) private(thread, lines, half, jb, j0, nb, j, q, p)
      thread = 0
      !$ thread = omp_get_thread_num()
      call c_f_pointer(conv%real_mem(thread), lines, [m, b])
      call c_f_pointer(conv%complex_mem(thread), half, [mh, b])
      !$omp do schedule(static)
      do jb = 1, (np + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, np - j0)
         lines = 0
         do j = 1, nb
            q = j0 + j - 1
            if (conv%periodic) then
               lines(1:np, j) = table(:, q)
            else
               do p = -(np - 1), np - 1
                  lines(modulo(p, m) + 1, j) = table(abs(p), q)
               end do
            end if
         end do
         call fftw_execute_dft_r2c(conv%double%columns_forward, lines, half)
         conv%spectrum(:, j0 + 1:j0 + nb) = half(:, 1:nb)
      end do
      !$omp end do
      !$omp end parallel
      allocate(conv%kernel(0:kh, mh))
      !$omp parallel num_threads(conv%threads) private(thread, half, jb, j0, nb, j, q)
      thread = 0
      !$ thread = omp_get_thread_num()
      call c_f_pointer(conv%complex_mem(thread), half, [m, b])
      !$omp do schedule(static)
      do jb = 1, (mh + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, mh - j0)
         half = 0
         do q = 0, np - 1
            half(q + 1, 1:nb) = conv%spectrum(j0 + 1:j0 + nb, q + 1)
         end do
         do q = np + 1, m - 1
            half(q + 1, 1:nb) = half(m - q + 1, 1:nb)
         end do
         call fftw_execute_dft(conv%double%rows_forward, half, half)
         ! Even kernel: the spectrum is real (the imaginary part is round-off).
         do j = 1, nb
            conv%kernel(:, j0 + j) = real(half(1:kh + 1, j), dp)/real(m, dp)**2
         end do
      end do
      !$omp end do
      !$omp end parallel
      ! A periodic table has zero mean (round-off aside): no zero-frequency response.
      if (conv%periodic) conv%kernel(0, 1) = 0
   end subroutine convolution_setup

   !> The double-precision plans, made on thread 0's buffers.
   subroutine make_plans_double(conv, flags)
      type(love_convolution), intent(inout) :: conv
      integer(c_int), intent(in) :: flags
      real(c_double), pointer :: lines(:, :)
      complex(c_double_complex), pointer :: half(:, :)
      integer(c_int) :: m, mh, b
      m = int(conv%m, c_int)
      mh = int(conv%mh, c_int)
      b = int(conv%block, c_int)
      call c_f_pointer(conv%real_mem(0), lines, [m, b])
      call c_f_pointer(conv%complex_mem(0), half, [m, b])
      associate(d => conv%double)
         d%columns_forward = fftw_plan_many_dft_r2c(1_c_int, [m], b, lines, [m], 1_c_int, m, &
            half, [mh], 1_c_int, mh, flags)
         d%columns_backward = fftw_plan_many_dft_c2r(1_c_int, [m], b, half, [mh], 1_c_int, mh, &
            lines, [m], 1_c_int, m, flags)
         d%rows_forward = fftw_plan_many_dft(1_c_int, [m], b, half, [m], 1_c_int, m, &
            half, [m], 1_c_int, m, FFTW_FORWARD, flags)
         d%rows_backward = fftw_plan_many_dft(1_c_int, [m], b, half, [m], 1_c_int, m, &
            half, [m], 1_c_int, m, FFTW_BACKWARD, flags)
      end associate
   end subroutine make_plans_double

   !> The float32 plans, made on thread 0's buffers.
   subroutine make_plans_single(conv, flags)
      type(love_convolution), intent(inout) :: conv
      integer(c_int), intent(in) :: flags
      real(c_float), pointer :: lines(:, :)
      complex(c_float_complex), pointer :: half(:, :)
      integer(c_int) :: m, mh, b
      m = int(conv%m, c_int)
      mh = int(conv%mh, c_int)
      b = int(conv%block, c_int)
      call c_f_pointer(conv%real_mem(0), lines, [m, b])
      call c_f_pointer(conv%complex_mem(0), half, [m, b])
      associate(s => conv%single)
         s%columns_forward = fftwf_plan_many_dft_r2c(1_c_int, [m], b, lines, [m], 1_c_int, m, &
            half, [mh], 1_c_int, mh, flags)
         s%columns_backward = fftwf_plan_many_dft_c2r(1_c_int, [m], b, half, [mh], 1_c_int, mh, &
            lines, [m], 1_c_int, m, flags)
         s%rows_forward = fftwf_plan_many_dft(1_c_int, [m], b, half, [m], 1_c_int, m, &
            half, [m], 1_c_int, m, FFTW_FORWARD, flags)
         s%rows_backward = fftwf_plan_many_dft(1_c_int, [m], b, half, [m], 1_c_int, m, &
            half, [m], 1_c_int, m, FFTW_BACKWARD, flags)
      end associate
   end subroutine make_plans_single

   !> result(i, j) = factor * sum_{k,l} I(i-k, j-l) field(k, l) over the NP x NP grid;
   !> with `in_place` instead of field and result, the field replaced by its result (the
   !> first pass reads all of it before the last writes).
   subroutine convolution_apply(conv, field, result, factor, in_place)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in), optional :: field(:, :)
      real(dp), intent(out), optional :: result(:, :)
      !> Multiplies the result (default 1): a compliance, folded into the last pass.
      real(dp), intent(in), optional :: factor
      real(dp), intent(inout), optional :: in_place(:, :)
      real(c_double), pointer :: lines(:, :)
      complex(c_double_complex), pointer :: half(:, :)
      real(dp) :: f
      integer :: np, m, mh, kh, b, thread, jb, j0, nb, j
      f = 1
      if (present(factor)) f = factor
      np = conv%np
      m = conv%m
      mh = conv%mh
      kh = m/2
      b = conv%block
      !$omp parallel num_threads(conv%threads) private(thread, lines, half, jb, j0, nb, j)
      thread = 0
      !$ thread = omp_get_thread_num()
      call c_f_pointer(conv%real_mem(thread), lines, [m, b])
      ! Pass 1: the data columns, zero-padded, into the half spectrum.
      call c_f_pointer(conv%complex_mem(thread), half, [mh, b])
      !$omp do schedule(static)
      do jb = 1, (np + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, np - j0)
         if (present(in_place)) then
            lines(1:np, 1:nb) = in_place(:, j0 + 1:j0 + nb)
         else
            lines(1:np, 1:nb) = field(:, j0 + 1:j0 + nb)
         end if
         lines(np + 1:, 1:nb) = 0
         lines(:, nb + 1:) = 0
         call fftw_execute_dft_r2c(conv%double%columns_forward, lines, half)
         conv%spectrum(:, j0 + 1:j0 + nb) = half(:, 1:nb)
      end do
      !$omp end do
      ! Pass 2: rows of the half spectrum, times the kernel's spectrum.
      call c_f_pointer(conv%complex_mem(thread), half, [m, b])
      !$omp do schedule(static)
      do jb = 1, (mh + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, mh - j0)
         do j = 1, np
            half(j, 1:nb) = conv%spectrum(j0 + 1:j0 + nb, j)
         end do
         half(np + 1:, 1:nb) = 0
         half(:, nb + 1:) = 0
         call fftw_execute_dft(conv%double%rows_forward, half, half)
         do j = 1, nb
            half(1:kh + 1, j) = half(1:kh + 1, j)*conv%kernel(:, j0 + j)
            half(kh + 2:m, j) = half(kh + 2:m, j)*conv%kernel(m - kh - 1:1:-1, j0 + j)
         end do
         call fftw_execute_dft(conv%double%rows_backward, half, half)
         do j = 1, np
            conv%spectrum(j0 + 1:j0 + nb, j) = half(j, 1:nb)
         end do
      end do
      !$omp end do
      ! Pass 3: the columns read back, cropped and scaled.
      call c_f_pointer(conv%complex_mem(thread), half, [mh, b])
      !$omp do schedule(static)
      do jb = 1, (np + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, np - j0)
         half(:, 1:nb) = conv%spectrum(:, j0 + 1:j0 + nb)
         half(:, nb + 1:) = 0
         call fftw_execute_dft_c2r(conv%double%columns_backward, half, lines)
         if (present(in_place)) then
            in_place(:, j0 + 1:j0 + nb) = f*lines(1:np, 1:nb)
         else
            result(:, j0 + 1:j0 + nb) = f*lines(1:np, 1:nb)
         end if
      end do
      !$omp end do
      !$omp end parallel
   end subroutine convolution_apply

   !> As convolution_apply, with float32 transforms (needs setup with single = .true.).
   !> The result in double (`result`) or, rounded once more, in float32 (`result32`); or
   !> a float32 field replaced by its float32 result (`in_place32`, instead of field and
   !> result).
   subroutine convolution_apply_single(conv, field, result, factor, result32, in_place32)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in), optional :: field(:, :)
      real(dp), intent(out), optional :: result(:, :)
      !> Multiplies the result (default 1): a compliance, folded into the last pass.
      real(dp), intent(in), optional :: factor
      real(sp), intent(out), optional :: result32(:, :)
      real(sp), intent(inout), optional :: in_place32(:, :)
      real(c_float), pointer :: lines(:, :)
      complex(c_float_complex), pointer :: half(:, :)
      real(dp) :: f
      integer :: np, m, mh, kh, b, thread, jb, j0, nb, j
      f = 1
      if (present(factor)) f = factor
      np = conv%np
      m = conv%m
      mh = conv%mh
      kh = m/2
      b = conv%block
      !$omp parallel num_threads(conv%threads) private(thread, lines, half, jb, j0, nb, j)
      thread = 0
      !$ thread = omp_get_thread_num()
      call c_f_pointer(conv%real_mem(thread), lines, [m, b])
      call c_f_pointer(conv%complex_mem(thread), half, [mh, b])
      !$omp do schedule(static)
      do jb = 1, (np + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, np - j0)
         if (present(in_place32)) then
            lines(1:np, 1:nb) = in_place32(:, j0 + 1:j0 + nb)
         else
            lines(1:np, 1:nb) = real(field(:, j0 + 1:j0 + nb), sp)
         end if
         lines(np + 1:, 1:nb) = 0
         lines(:, nb + 1:) = 0
         call fftwf_execute_dft_r2c(conv%single%columns_forward, lines, half)
         conv%spectrum32(:, j0 + 1:j0 + nb) = half(:, 1:nb)
      end do
      !$omp end do
      call c_f_pointer(conv%complex_mem(thread), half, [m, b])
      !$omp do schedule(static)
      do jb = 1, (mh + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, mh - j0)
         do j = 1, np
            half(j, 1:nb) = conv%spectrum32(j0 + 1:j0 + nb, j)
         end do
         half(np + 1:, 1:nb) = 0
         half(:, nb + 1:) = 0
         call fftwf_execute_dft(conv%single%rows_forward, half, half)
         do j = 1, nb
            half(1:kh + 1, j) = half(1:kh + 1, j)*real(conv%kernel(:, j0 + j), sp)
            half(kh + 2:m, j) = half(kh + 2:m, j)*real(conv%kernel(m - kh - 1:1:-1, j0 + j), sp)
         end do
         call fftwf_execute_dft(conv%single%rows_backward, half, half)
         do j = 1, np
            conv%spectrum32(j0 + 1:j0 + nb, j) = half(j, 1:nb)
         end do
      end do
      !$omp end do
      call c_f_pointer(conv%complex_mem(thread), half, [mh, b])
      !$omp do schedule(static)
      do jb = 1, (np + b - 1)/b
         j0 = (jb - 1)*b
         nb = min(b, np - j0)
         half(:, 1:nb) = conv%spectrum32(:, j0 + 1:j0 + nb)
         half(:, nb + 1:) = 0
         call fftwf_execute_dft_c2r(conv%single%columns_backward, half, lines)
         if (present(result32)) then
            result32(:, j0 + 1:j0 + nb) = real(f*real(lines(1:np, 1:nb), dp), sp)
         else if (present(in_place32)) then
            in_place32(:, j0 + 1:j0 + nb) = real(f*real(lines(1:np, 1:nb), dp), sp)
         else
            result(:, j0 + 1:j0 + nb) = f*real(lines(1:np, 1:nb), dp)
         end if
      end do
      !$omp end do
      !$omp end parallel
   end subroutine convolution_apply_single

   !> The central coefficients of the inverse of the convolution on the padded periodic
   !> grid (on the cell, periodic): taps(a, b), a, b = 0..2, at offsets (+-a, +-b)
   !> (dimensionless, for the table's units; a discrete form of the |q| operator, E* |q| / 2
   !> in the continuum). A periodic kernel has no mean (spectrum 0 at zero frequency):
   !> its inverse is taken on the other frequencies (a pseudo-inverse, 0 at zero
   !> frequency). `ok` is false when another coefficient of the kernel spectrum is not
   !> positive, so that it has no inverse.
   !> The inverse's spectrum is real and even in both frequencies, so each tap is a
   !> cosine sum over the quarter k1, k2 = 0..M/2 (weight 2 off the lines 0 and M/2):
   !> inverse_tap_sums over M^4.
   subroutine inverse_kernel_taps(conv, taps, ok)
      type(love_convolution), intent(in) :: conv
      real(dp), intent(out) :: taps(0:2, 0:2)
      logical, intent(out) :: ok
      integer :: kh, k
      taps = 0
      ok = conv%np >= 3
      if (.not. ok) return
      if (conv%periodic) then
         ok = minval(conv%kernel(1:, :)) > 0 .and. minval(conv%kernel(0, 2:)) > 0
      else
         ok = minval(conv%kernel) > 0
      end if
      if (.not. ok) return
      kh = conv%m/2
      taps = inverse_tap_sums(conv%kernel, conv%m, [(k, k = 0, kh)], mirror_weights(conv%m), [(k, k = 0, kh)], &
         mirror_weights(conv%m), conv%threads, merge([1, 1], [0, 0], conv%periodic))/real(conv%m, dp)**4
   end subroutine inverse_kernel_taps

   !> How often each frequency k = 0 .. m/2 of a spectrum even in k occurs among all m:
   !> once at 0 and at m/2 (m even), twice (k and m - k) otherwise.
   pure function mirror_weights(m) result(w)
      integer, intent(in) :: m
      real(dp) :: w(m/2 + 1)
      w = 2
      w(1) = 1
      if (mod(m, 2) == 0) w(m/2 + 1) = 1
   end function mirror_weights

   !> The sums behind the preconditioner's taps (inverse_kernel_taps; femcod-mpi's ranks
   !> each over their own frequencies): sums(a, b), a, b = 0..2, the sum over the kernel's
   !> columns k of cos_a(k) times the sum over its rows l of cos_b(l) / kernel(l, k), with
   !> cos_a(k) = column_weight(k) cos(2 pi a column_freq(k) / m) and cos_b(l) likewise for
   !> the rows. `zero_at` (row, column; 1-based; 0, 0: none): the zero frequency, left out
   !> (the periodic kernel's, which has no inverse). The rows summed in order for each
   !> column, then the columns in order: the same bits on any number of threads. Not
   !> divided by m^4.
   function inverse_tap_sums(kernel, m, row_freq, row_weight, column_freq, column_weight, threads, zero_at) &
      result(sums)
      real(dp), intent(in) :: kernel(:, :), row_weight(:), column_weight(:)
      integer, intent(in) :: m, row_freq(:), column_freq(:), threads, zero_at(2)
      real(dp) :: sums(0:2, 0:2)
      real(dp), parameter :: two_pi = 8*atan(1.0_dp)
      real(dp), allocatable :: inner(:, :), row_cos(:, :), column_cos(:, :)
      integer :: k, l, a
      real(dp) :: r
      allocate(inner(0:2, size(kernel, 2)), row_cos(size(row_freq), 0:2), column_cos(size(column_freq), 0:2))
      do a = 0, 2
         row_cos(:, a) = row_weight*cos(two_pi*real(a*row_freq, dp)/real(m, dp))
         column_cos(:, a) = column_weight*cos(two_pi*real(a*column_freq, dp)/real(m, dp))
      end do
      ! inner(b, k) = sum over l of row_cos(l, b) / kernel(l, k)
      !$omp parallel do num_threads(threads) private(l, r)
      do k = 1, size(kernel, 2)
         inner(:, k) = 0
         do l = 1, size(kernel, 1)
            r = 1/kernel(l, k)
            if (l == zero_at(1) .and. k == zero_at(2)) r = 0
            inner(:, k) = inner(:, k) + row_cos(l, :)*r
         end do
      end do
      sums = 0
      do a = 0, 2
         do k = 1, size(kernel, 2)
            sums(a, :) = sums(a, :) + inner(:, k)*column_cos(k, a)
         end do
      end do
   end function inverse_tap_sums

   subroutine convolution_free(conv)
      type(love_convolution), intent(inout) :: conv
      integer :: t
      if (conv%m == 0) return
      call fftw_destroy_plan(conv%double%columns_forward)
      call fftw_destroy_plan(conv%double%columns_backward)
      call fftw_destroy_plan(conv%double%rows_forward)
      call fftw_destroy_plan(conv%double%rows_backward)
      if (conv%has_single) then
         call fftwf_destroy_plan(conv%single%columns_forward)
         call fftwf_destroy_plan(conv%single%columns_backward)
         call fftwf_destroy_plan(conv%single%rows_forward)
         call fftwf_destroy_plan(conv%single%rows_backward)
      end if
      do t = 0, conv%threads - 1
         call fftw_free(conv%real_mem(t))
         call fftw_free(conv%complex_mem(t))
      end do
      deallocate(conv%real_mem, conv%complex_mem)
      call fftw_free(conv%spectrum_mem)
      nullify(conv%spectrum, conv%spectrum32)
      if (allocated(conv%kernel)) deallocate(conv%kernel)
      conv%m = 0
      conv%has_single = .false.
   end subroutine convolution_free

   !> The transform grid for the Love table I(0:np-1, 0:np-1) (the free half-space's, or
   !> the periodic cell's with `periodic`), the composite compliance c and the springs' s
   !> (nm/nN). `ok` false when C's spectrum is not positive (smallest returned in
   !> `smallest`, nm/nN).
   subroutine gap_transform_setup(t, table, c, s, periodic, ok, smallest)
      type(gap_transform), intent(inout) :: t
      real(dp), intent(in) :: table(0:, 0:), c, s
      logical, intent(in) :: periodic
      logical, intent(out) :: ok
      real(dp), intent(out) :: smallest
      integer :: np, m, p, q, i, j
      np = size(table, 1)
      m = merge(np, 2*np, periodic)
      t%np = np
      t%m = m
      t%periodic = periodic
      call threaded_2d_plans(m, t%real_mem, t%complex_mem, t%field, t%spectrum, t%forward, t%backward)
      ! The kernel on the transform grid: offsets 0..NP-1 and -(NP-1)..-1 wrapped (free;
      ! offset NP is never reached by two pixels of the grid), or the periodic cell.
      t%field = 0
      do j = 1, m
         q = j - 1
         if (q > m/2) q = q - m
         do i = 1, m
            p = i - 1
            if (p > m/2) p = p - m
            if (periodic) then
               t%field(i, j) = table(i - 1, j - 1)
            else if (abs(p) < np .and. abs(q) < np) then
               t%field(i, j) = table(abs(p), abs(q))
            end if
         end do
      end do
      call fftw_execute_dft_r2c(t%forward, t%field, t%spectrum)
      ! The kernel is even in both offsets: its spectrum is real.
      t%compliance = c*real(t%spectrum, dp) + s
      ! A periodic cell: no zero-frequency compliance (the mean gap is a constraint).
      if (periodic) t%compliance(1, 1) = 1
      smallest = minval(t%compliance)
      ok = smallest > 0
      if (.not. ok) return
      t%stiffness = 1/t%compliance/real(m, dp)**2
      t%compliance = t%compliance/real(m, dp)**2
      if (periodic) then
         t%stiffness(1, 1) = 0
         t%compliance(1, 1) = 0
      end if
   end subroutine gap_transform_setup

   !> An M x M real field and its half spectrum on FFTW's aligned memory, with the 2-D
   !> r2c and c2r plans between them on OpenMP's threads (FFTW's threaded plans); plans
   !> made after these are single-threaded again, as the convolution's blocks expect.
   !> FFTW_ESTIMATE's plans, or FFTW_MEASURE's with `measure` true.
   subroutine threaded_2d_plans(m, real_mem, complex_mem, field, spectrum, forward, backward, measure)
      integer, intent(in) :: m
      type(c_ptr), intent(out) :: real_mem, complex_mem, forward, backward
      real(c_double), pointer, intent(out) :: field(:, :)
      complex(c_double_complex), pointer, intent(out) :: spectrum(:, :)
      logical, intent(in), optional :: measure
      integer :: threads
      integer(c_int) :: flags
      flags = FFTW_ESTIMATE
      if (present(measure)) then
         if (measure) flags = FFTW_MEASURE
      end if
      real_mem = fftw_alloc_real(int(m, c_size_t)**2)
      complex_mem = fftw_alloc_complex(int(m/2 + 1, c_size_t)*int(m, c_size_t))
      call c_f_pointer(real_mem, field, [m, m])
      call c_f_pointer(complex_mem, spectrum, [m/2 + 1, m])
      threads = 1
      !$ threads = omp_get_max_threads()
      if (fftw_init_threads() == 0) threads = 1
      call fftw_plan_with_nthreads(int(threads, c_int))
      forward = fftw_plan_dft_r2c_2d(int(m, c_int), int(m, c_int), field, spectrum, flags)
      backward = fftw_plan_dft_c2r_2d(int(m, c_int), int(m, c_int), spectrum, field, flags)
      call fftw_plan_with_nthreads(1_c_int)
   end subroutine threaded_2d_plans

   !> The pair's plans on M x M (`measure`: FFTW_MEASURE instead of FFTW_ESTIMATE) and a
   !> field of zeros.
   subroutine transform_pair_setup(pair, m, measure)
      type(transform_pair), intent(inout) :: pair
      integer, intent(in) :: m
      logical, intent(in) :: measure
      pair%m = m
      call threaded_2d_plans(m, pair%real_mem, pair%complex_mem, pair%field, pair%spectrum, pair%forward, &
         pair%backward, measure)
      pair%field = 0
   end subroutine transform_pair_setup

   !> The field to its half spectrum and back (unnormalised: the field comes back M^2
   !> times itself).
   subroutine transform_pair_apply(pair)
      type(transform_pair), intent(inout) :: pair
      call fftw_execute_dft_r2c(pair%forward, pair%field, pair%spectrum)
      call fftw_execute_dft_c2r(pair%backward, pair%spectrum, pair%field)
   end subroutine transform_pair_apply

   subroutine transform_pair_free(pair)
      type(transform_pair), intent(inout) :: pair
      if (.not. associated(pair%field)) return
      call free_2d_plans(pair%real_mem, pair%complex_mem, pair%field, pair%spectrum, pair%forward, pair%backward)
   end subroutine transform_pair_free

   !> Undo threaded_2d_plans: the plans destroyed, FFTW's memory freed.
   subroutine free_2d_plans(real_mem, complex_mem, field, spectrum, forward, backward)
      type(c_ptr), intent(inout) :: real_mem, complex_mem, forward, backward
      real(c_double), pointer, intent(inout) :: field(:, :)
      complex(c_double_complex), pointer, intent(inout) :: spectrum(:, :)
      call fftw_destroy_plan(forward)
      call fftw_destroy_plan(backward)
      call fftw_free(real_mem)
      call fftw_free(complex_mem)
      nullify(field, spectrum)
   end subroutine free_2d_plans

   !> out = L in on the transform grid (M x M), L the compliance or the stiffness
   !> (`which`: SPECTRUM_COMPLIANCE or SPECTRUM_STIFFNESS).
   subroutine gap_transform_apply(t, which, in, out)
      type(gap_transform), intent(inout) :: t
      integer, intent(in) :: which
      real(dp), intent(in) :: in(:, :)
      real(dp), intent(out) :: out(:, :)
      integer :: i, j
      !$omp parallel do private(i)
      do j = 1, t%m
         do i = 1, t%m
            t%field(i, j) = in(i, j)
         end do
      end do
      !$omp end parallel do
      call fftw_execute_dft_r2c(t%forward, t%field, t%spectrum)
      if (which == SPECTRUM_COMPLIANCE) then
         call multiply(t%compliance)
      else
         call multiply(t%stiffness)
      end if
      call fftw_execute_dft_c2r(t%backward, t%spectrum, t%field)
      !$omp parallel do private(i)
      do j = 1, t%m
         do i = 1, t%m
            out(i, j) = t%field(i, j)
         end do
      end do
      !$omp end parallel do
   contains
      subroutine multiply(multiplier)
         real(dp), intent(in) :: multiplier(:, :)
         integer :: ii, jj
         !$omp parallel do private(ii)
         do jj = 1, t%m
            do ii = 1, t%m/2 + 1
               t%spectrum(ii, jj) = t%spectrum(ii, jj)*multiplier(ii, jj)
            end do
         end do
         !$omp end parallel do
      end subroutine multiply
   end subroutine gap_transform_apply

   subroutine gap_transform_free(t)
      type(gap_transform), intent(inout) :: t
      if (.not. associated(t%field)) return
      call free_2d_plans(t%real_mem, t%complex_mem, t%field, t%spectrum, t%forward, t%backward)
      if (allocated(t%compliance)) deallocate(t%compliance)
      if (allocated(t%stiffness)) deallocate(t%stiffness)
   end subroutine gap_transform_free

   !> Plans and spectra of the tangential operator from its tables xx, yy, xy (nm/nN,
   !> offsets p, q = 0 .. NP-1 along the rows and the columns; femcod_cerruti's
   !> tangential_tables), placed at the offsets -(NP-1) .. NP-1 of the padded grid with
   !> xy's signs (odd in both offsets).
   subroutine shear_transform_setup(t, xx, yy, xy)
      type(shear_transform), intent(inout) :: t
      real(dp), intent(in) :: xx(0:, 0:), yy(0:, 0:), xy(0:, 0:)
      integer :: np, m
      np = size(xx, 1)
      m = 2*np
      t%np = np
      t%m = m
      call threaded_2d_plans(m, t%real_mem, t%complex_mem, t%field, t%spectrum, t%forward, t%backward)
      call keep_shear_spectra(t, spectrum_of(xx, .false.), spectrum_of(yy, .false.), spectrum_of(xy, .true.))
   contains
      !> The real spectrum of a table placed at the offsets (with the signs of an odd
      !> table).
      function spectrum_of(table, odd) result(spec)
         real(dp), intent(in) :: table(0:, 0:)
         logical, intent(in) :: odd
         real(dp), allocatable :: spec(:, :)
         integer :: i, j, p, q
         t%field = 0
         do j = 1, m
            q = j - 1
            if (q > m/2) q = q - m
            if (abs(q) >= np) cycle
            do i = 1, m
               p = i - 1
               if (p > m/2) p = p - m
               if (abs(p) >= np) cycle
               t%field(i, j) = table(abs(p), abs(q))
               if (odd) t%field(i, j) = t%field(i, j)*sign(1, p)*sign(1, q)
            end do
         end do
         call fftw_execute_dft_r2c(t%forward, t%field, t%spectrum)
         spec = real(t%spectrum, dp)
      end function spectrum_of
   end subroutine shear_transform_setup

   !> The shear transform's spectra xx, yy, xy (nm/nN, the r2c layout) divided by M^2 for
   !> FFTW's unnormalised transforms, the largest eigenvalue of their 2 x 2 matrix over
   !> the frequencies, and the x component's spectrum buffer.
   subroutine keep_shear_spectra(t, xx, yy, xy)
      type(shear_transform), intent(inout) :: t
      real(dp), intent(in) :: xx(:, :), yy(:, :), xy(:, :)
      t%xx = xx/real(t%m, dp)**2
      t%yy = yy/real(t%m, dp)**2
      t%xy = xy/real(t%m, dp)**2
      t%largest = maxval((xx + yy)/2 + sqrt(((xx - yy)/2)**2 + xy**2))
      allocate(t%along_x(t%m/2 + 1, t%m))
   end subroutine keep_shear_spectra

   !> The tangential operator of a periodic cell (M = NP, no padding) from its spectra
   !> (nm/nN, the r2c layout NP/2 + 1 x NP: femcod_cerruti's periodic_tangential_spectra).
   subroutine shear_transform_setup_periodic(t, xx, yy, xy)
      type(shear_transform), intent(inout) :: t
      real(dp), intent(in) :: xx(:, :), yy(:, :), xy(:, :)
      integer :: m
      m = size(xx, 2)
      t%np = m
      t%m = m
      call threaded_2d_plans(m, t%real_mem, t%complex_mem, t%field, t%spectrum, t%forward, t%backward)
      call keep_shear_spectra(t, xx, yy, xy)
   end subroutine shear_transform_setup_periodic

   !> (ux, uy) = the tangential operator applied to (tx, ty), all NP x NP (nN in, nm out).
   subroutine shear_transform_apply(t, tx, ty, ux, uy)
      type(shear_transform), intent(inout) :: t
      real(dp), intent(in) :: tx(:, :), ty(:, :)
      real(dp), intent(out) :: ux(:, :), uy(:, :)
      complex(dp) :: sx, sy
      integer :: i, j
      call forward(tx)
      !$omp parallel do private(i)
      do j = 1, t%m
         do i = 1, t%m/2 + 1
            t%along_x(i, j) = t%spectrum(i, j)
         end do
      end do
      !$omp end parallel do
      call forward(ty)
      ! The y component's spectrum in t%spectrum, the x component's in along_x.
      !$omp parallel do private(i, sx, sy)
      do j = 1, t%m
         do i = 1, t%m/2 + 1
            sx = t%along_x(i, j)
            sy = t%spectrum(i, j)
            t%along_x(i, j) = t%xx(i, j)*sx + t%xy(i, j)*sy
            t%spectrum(i, j) = t%xy(i, j)*sx + t%yy(i, j)*sy
         end do
      end do
      !$omp end parallel do
      call backward(uy)
      !$omp parallel do private(i)
      do j = 1, t%m
         do i = 1, t%m/2 + 1
            t%spectrum(i, j) = t%along_x(i, j)
         end do
      end do
      !$omp end parallel do
      call backward(ux)
   contains
      subroutine forward(in)
         real(dp), intent(in) :: in(:, :)
         integer :: ii, jj
         !$omp parallel do private(ii)
         do jj = 1, t%m
            do ii = 1, t%m
               t%field(ii, jj) = 0
               if (ii <= t%np .and. jj <= t%np) t%field(ii, jj) = in(ii, jj)
            end do
         end do
         !$omp end parallel do
         call fftw_execute_dft_r2c(t%forward, t%field, t%spectrum)
      end subroutine forward
      subroutine backward(out)
         real(dp), intent(out) :: out(:, :)
         integer :: ii, jj
         call fftw_execute_dft_c2r(t%backward, t%spectrum, t%field)
         !$omp parallel do private(ii)
         do jj = 1, t%np
            do ii = 1, t%np
               out(ii, jj) = t%field(ii, jj)
            end do
         end do
         !$omp end parallel do
      end subroutine backward
   end subroutine shear_transform_apply

   subroutine shear_transform_free(t)
      type(shear_transform), intent(inout) :: t
      if (.not. associated(t%field)) return
      call free_2d_plans(t%real_mem, t%complex_mem, t%field, t%spectrum, t%forward, t%backward)
      if (allocated(t%along_x)) deallocate(t%along_x, t%xx, t%yy, t%xy)
   end subroutine shear_transform_free

   !> field = the inverse 2-D transform of a real, even spectrum's half (kh + 1) x np
   !> (kh = np/2; FFTW's c2r of a row-major np x np transform: the first index the halved
   !> frequency), not normalised (FFTW's sum). On FFTW's own aligned memory.
   subroutine inverse_half_spectrum(spectrum, field)
      complex(dp), intent(in) :: spectrum(:, :)
      real(dp), intent(out) :: field(:, :)
      type(c_ptr) :: plan, in_mem, out_mem
      complex(c_double_complex), pointer :: values(:, :)
      real(c_double), pointer :: out(:, :)
      integer :: np, kh
      np = size(field, 1)
      kh = size(spectrum, 1) - 1
      in_mem = fftw_alloc_complex(int(kh + 1, c_size_t)*int(np, c_size_t))
      out_mem = fftw_alloc_real(int(np, c_size_t)*int(np, c_size_t))
      call c_f_pointer(in_mem, values, [kh + 1, np])
      call c_f_pointer(out_mem, out, [np, np])
      plan = fftw_plan_dft_c2r_2d(int(np, c_int), int(np, c_int), values, out, FFTW_ESTIMATE)
      values = spectrum
      call fftw_execute_dft_c2r(plan, values, out)
      field = out
      call fftw_destroy_plan(plan)
      call fftw_free(in_mem)
      call fftw_free(out_mem)
   end subroutine inverse_half_spectrum

   !> field = the backward (unnormalised) complex 2-D transform of `spectrum`, both n x n,
   !> planned on the caller's arrays.
   subroutine inverse_complex_transform(spectrum, field)
      complex(c_double_complex), intent(inout), target, contiguous :: spectrum(:, :)
      complex(c_double_complex), intent(out), target, contiguous :: field(:, :)
      type(c_ptr) :: plan
      plan = fftw_plan_dft_2d(int(size(field, 2), c_int), int(size(field, 1), c_int), spectrum, field, FFTW_BACKWARD, &
         FFTW_ESTIMATE)
      call fftw_execute_dft(plan, spectrum, field)
      call fftw_destroy_plan(plan)
   end subroutine inverse_complex_transform

   !> a = the forward (unnormalised) complex 2-D transform of `a`, in place, planned on the
   !> caller's array (FFTW_ESTIMATE does not write it while planning).
   subroutine forward_complex_transform(a)
      complex(c_double_complex), intent(inout), target, contiguous :: a(:, :)
      type(c_ptr) :: plan
      plan = fftw_plan_dft_2d(int(size(a, 2), c_int), int(size(a, 1), c_int), a, a, FFTW_FORWARD, FFTW_ESTIMATE)
      call fftw_execute_dft(plan, a, a)
      call fftw_destroy_plan(plan)
   end subroutine forward_complex_transform

   !> The plan of r2c transforms of `line` (n real values) into `spectrum` (n/2 + 1).
   subroutine line_transform_setup(t, line, spectrum)
      type(line_transform), intent(inout) :: t
      real(dp), intent(inout), target, contiguous :: line(:)
      complex(c_double_complex), intent(inout), target, contiguous :: spectrum(:)
      t%plan = fftw_plan_dft_r2c_1d(int(size(line), c_int), line, spectrum, FFTW_ESTIMATE)
      t%made = .true.
   end subroutine line_transform_setup

   subroutine line_transform_apply(t, line, spectrum)
      type(line_transform), intent(inout) :: t
      real(dp), intent(inout), target, contiguous :: line(:)
      complex(c_double_complex), intent(inout), target, contiguous :: spectrum(:)
      call fftw_execute_dft_r2c(t%plan, line, spectrum)
   end subroutine line_transform_apply

   subroutine line_transform_free(t)
      type(line_transform), intent(inout) :: t
      if (t%made) call fftw_destroy_plan(t%plan)
      t%made = .false.
   end subroutine line_transform_free
end module femcod_convolution
