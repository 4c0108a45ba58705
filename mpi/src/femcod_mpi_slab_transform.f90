!> One rank's part of the 2-D real transform of an NP x NP grid split in column slabs
!> across the ranks (femcod_mpi_cg's Love convolution and femcod_mpi_shear's Cerruti
!> operator both apply theirs through it): real-to-complex transforms of length M down
!> this rank's columns (M = 2 NP zero-padded on the free surface, NP on the periodic cell;
!> only NP of the M are not zero), the distributed transpose of the (M/2 + 1) x NP half
!> spectrum, and complex transforms of length M along the rows of this rank's
!> frequencies; and back the same way. Only the non-zero half is transformed and moved.
!> The transpose is FFTW-MPI's, or, when every rank is on one node, a copy through memory
!> the node's ranks share: each rank's columns live in one MPI-3 shared window, and each
!> rank reads (and writes back) its frequencies of every rank's columns after a barrier.
!> A transpose moves values and computes nothing, so both give the same bits.
!> The spectrum (M, freqs) lies in `rows` between slab_forward and slab_backward, where
!> the operator multiplies it. float32 views of the same memory with their own plans.
!>
!> A convolution with a real kernel spectrum (slab_convolve, slab_convolve_single) does
!> its row step in one pass, as the serial convolution's second pass does
!> (femcod_convolution): each block of ROW_BLOCK rows is zero-padded to M in a buffer of
!> its thread that stays in cache, transformed, multiplied, transformed back, and its
!> first NP values kept; the rows are never spread to M in place. On one node the block
!> is read straight from every rank's columns in the shared window and written back
!> there: that copy is the transpose, and the packed rows are not used.
!>
!> The transposed rows are extended to M in place: zero-padded (a field), or evenly or
!> oddly (a kernel table placed at the offsets -(NP-1) .. NP-1, each rank from its own
!> columns).
!>
!> Besides, the complex 2-D backward transform of a field in the same column slabs
!> (slab_dft: femcod_mpi_generate's surface spectrum), so that every plan femcod-mpi makes
!> is made here.
!>
!> No I/O and no stop: errors come back in a status.
module femcod_mpi_slab_transform
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_double, c_double_complex, c_float, c_float_complex, &
      c_intptr_t, c_int, c_f_pointer, c_associated, c_size_t
   !$ use omp_lib, only: omp_get_max_threads, omp_get_thread_num
   use mpi_f08, only: MPI_Comm, MPI_COMM_NULL, MPI_Win, MPI_WIN_NULL, MPI_INFO_NULL, MPI_ADDRESS_KIND, &
      MPI_COMM_TYPE_SHARED, MPI_MODE_NOCHECK, MPI_Comm_split_type, MPI_Comm_size, MPI_Comm_rank, MPI_Comm_free, &
      MPI_Win_allocate_shared, MPI_Win_shared_query, MPI_Win_lock_all, MPI_Win_unlock_all, MPI_Win_sync, &
      MPI_Win_free, MPI_Barrier, operator(/=)
   use femcod_fftw_mpi, only: fftw_mpi_local_size_many_transposed, fftw_mpi_plan_many_transpose, fftw_mpi_execute_r2r, &
      fftw_plan_many_dft_r2c, fftw_plan_many_dft_c2r, fftw_plan_many_dft, fftw_execute_dft_r2c, fftw_execute_dft_c2r, &
      fftw_execute_dft, fftw_alloc_complex, fftw_free, fftw_destroy_plan, FFTW_ESTIMATE, FFTW_MEASURE, FFTW_FORWARD, &
      FFTW_BACKWARD, FFTW_MPI_DEFAULT_BLOCK, fftw_mpi_local_size_many, fftw_mpi_plan_many_dft, fftw_mpi_execute_dft, &
      fftwf_mpi_plan_many_transpose, fftwf_mpi_execute_r2r, &
      fftwf_plan_many_dft_r2c, fftwf_plan_many_dft_c2r, fftwf_plan_many_dft, fftwf_execute_dft_r2c, &
      fftwf_execute_dft_c2r, fftwf_execute_dft, fftwf_destroy_plan
   use femcod_kinds, only: dp, sp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_strings, only: int_str
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: slab_transform, slab_setup, slab_free, slab_forward, slab_forward_field, slab_backward, &
      slab_convolve, slab_convolve_single, slab_permute, slab_release_rows
   public :: PAD_ZEROS, EXTEND_EVEN, EXTEND_ODD
   public :: slab_dft, slab_dft_setup, slab_dft_backward, slab_dft_free, on_one_node, shared_transposes

   !> How the transposed rows of NP become rows of M (module header).
   integer, parameter :: PAD_ZEROS = 0, EXTEND_EVEN = 1, EXTEND_ODD = -1
   !> Bytes to which the shared window's parts are aligned (FFTW's SIMD wants 16 to 64).
   integer, parameter :: ALIGNMENT = 64
   !> Rows per block of the one-pass row step: 8 rows of M = 8192 are 1 MB of double
   !> complex (femcod_convolution's lines_per_block).
   integer, parameter :: ROW_BLOCK = 8
   !> The environment variable that keeps FFTW-MPI's transposes on one node (`fftw-mpi`).
   character(len=*), parameter :: TRANSPOSES_VARIABLE = "FEMCOD_MPI_TRANSPOSES"

   type :: slab_transform
      type(MPI_Comm) :: comm = MPI_COMM_NULL
      !> Grid side; this rank's first column (0-based) and number of columns; columns per
      !> rank (FFTW-MPI's block; the last ranks may have fewer).
      integer :: np = 0, j0 = 0, nj = 0, block_columns = 0
      !> The transform length m, its half spectrum mh = m/2 + 1; this rank's frequencies
      !> (0-based first, number) after the transpose.
      integer :: m = 0, mh = 0, freq_start = 0, freqs = 0
      !> Down the columns: in-place r2c / c2r, the real view (2 mh, nj), the complex
      !> (mh, nj); along the rows: the complex view (m, freqs), its first np*freqs values
      !> the transpose's (np, freqs).
      type(c_ptr) :: column_memory = c_null_ptr, row_memory = c_null_ptr
      !> Complex values of the row memory (FFTW-MPI's transpose may want more than m freqs).
      integer(c_size_t) :: row_values_count = 0
      real(c_double), pointer :: column_real(:, :) => null(), column_flat(:) => null(), row_flat(:) => null()
      complex(c_double_complex), pointer :: columns(:, :) => null(), rows(:, :) => null(), row_values(:) => null()
      type(c_ptr) :: columns_forward = c_null_ptr, columns_backward = c_null_ptr, rows_forward = c_null_ptr, &
         rows_backward = c_null_ptr, to_rows = c_null_ptr, to_columns = c_null_ptr
      !> float32 views of the same memory and their plans (made with `single`).
      logical :: has_single = .false.
      real(c_float), pointer :: column32_real(:, :) => null(), column32_flat(:) => null(), row32_flat(:) => null()
      complex(c_float_complex), pointer :: columns32(:, :) => null(), rows32(:, :) => null(), &
         row32_values(:) => null()
      type(c_ptr) :: columns_forward32 = c_null_ptr, columns_backward32 = c_null_ptr, rows_forward32 = c_null_ptr, &
         rows_backward32 = c_null_ptr, to_rows32 = c_null_ptr, to_columns32 = c_null_ptr
      !> The one-pass row step (module header): each thread's buffer of ROW_BLOCK rows of m
      !> (0:threads-1), and plans for one block in place, double and float32.
      type(c_ptr), allocatable :: line_memory(:)
      type(c_ptr) :: block_forward = c_null_ptr, block_backward = c_null_ptr, block_forward32 = c_null_ptr, &
         block_backward32 = c_null_ptr
      !> Wall seconds so far in the transforms (the 1-D transforms, the multiplications
      !> between them) and in FFTW-MPI's transposes.
      real(dp) :: transform_seconds = 0, communication_seconds = 0
      !> The transpose through shared memory (module header): the window of every rank's
      !> columns and each rank's columns in it, (0:ranks-1); not on_node: FFTW-MPI's.
      logical :: on_node = .false.
      type(MPI_Win) :: window = MPI_WIN_NULL
      type(rank_columns), allocatable :: peer(:)
      !> Columns the ranks hold in another order than the grid's (femcod_mpi_gap_transform's
      !> pixel and padding columns): natural(P), the position along a row (1-based) of the
      !> P-th value of a transposed row; not allocated: the grid's own order.
      integer, allocatable :: natural(:)
   end type slab_transform

   !> One rank's columns in the shared window: their first column (0-based) in the grid, and
   !> the half spectra (mh, count) in double and, over the same memory, in float32.
   type :: rank_columns
      integer :: first = 0
      complex(c_double_complex), pointer, contiguous :: z(:, :) => null()
      complex(c_float_complex), pointer, contiguous :: c(:, :) => null()
   end type rank_columns

   !> The complex 2-D backward DFT of an NP x NP field in column slabs: this rank's columns
   !> of the input and of the output (np, nj; FFTW's memory), and the plan between them.
   type :: slab_dft
      type(c_ptr) :: input_memory = c_null_ptr, output_memory = c_null_ptr, plan = c_null_ptr
      complex(c_double_complex), pointer :: input(:, :) => null(), output(:, :) => null()
   end type slab_dft

contains

   !> The transform of this rank's columns j0 + 1 .. j0 + nj of the NP x NP grid (every
   !> rank's block_columns, but the last ranks'), zero-padded to 2 NP or, with `periodic`,
   !> cyclic; measured plans with `measure`, the float32 ones too with `single`.
   !> Collective over `comm`.
   subroutine slab_setup(t, comm, np, j0, nj, block_columns, periodic, measure, single, status)
      type(slab_transform), intent(inout) :: t
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, j0, nj, block_columns
      logical, intent(in) :: periodic, measure, single
      type(status_type), intent(inout) :: status
      integer(c_intptr_t) :: alloc, dims(2), local_columns, column_start, local_freqs, freq_start
      integer(c_int) :: flags
      call slab_free(t)
      t%comm = comm
      t%np = np
      t%j0 = j0
      t%nj = nj
      t%block_columns = block_columns
      t%m = merge(np, 2*np, periodic)
      t%mh = t%m/2 + 1
      ! The transpose of the half spectrum: [np][mh] complex by columns (blocks of
      ! block_columns) to [mh][np] by frequencies (FFTW's default block).
      dims = [integer(c_intptr_t) :: np, t%mh]
      alloc = fftw_mpi_local_size_many_transposed(2_c_int, dims, 2_c_intptr_t, int(block_columns, c_intptr_t), &
         FFTW_MPI_DEFAULT_BLOCK, comm%MPI_VAL, local_columns, column_start, local_freqs, freq_start)
      if (int(local_columns) /= nj .or. int(column_start) /= j0) then
         call set_error(status, STATUS_NUMERICAL, "FFTW-MPI splits the columns otherwise than the solver: "// &
            int_str(int(local_columns))//" from "//int_str(int(column_start))//" where this rank has "// &
            int_str(nj)//" from "//int_str(j0))
         return
      end if
      t%freqs = int(local_freqs)
      t%freq_start = int(freq_start)
      call node_window_setup(t)
      if (.not. t%on_node) &
         t%column_memory = fftw_alloc_complex(int(max(alloc/2, int(t%mh, c_intptr_t)*nj, 1_c_intptr_t), c_size_t))
      t%row_values_count = int(max(alloc/2, int(t%m, c_intptr_t)*t%freqs, 1_c_intptr_t), c_size_t)
      call allocate_rows(t)
      flags = FFTW_ESTIMATE
      if (measure) flags = FFTW_MEASURE
      call make_plans(t, flags, status)
      if (status%code /= 0) return
      t%has_single = single
      if (single) call make_single_plans(t, flags, status)
   end subroutine slab_setup

   !> The double-precision views of the transform memory and their plans: the columns'
   !> r2c and c2r of length m, the rows' complex transforms of length m, FFTW-MPI's two
   !> transposes.
   subroutine make_plans(t, flags, status)
      type(slab_transform), intent(inout) :: t
      integer(c_int), intent(in) :: flags
      type(status_type), intent(inout) :: status
      integer(c_int) :: m, mh, nj, freqs
      complex(c_double_complex), pointer :: lines(:, :)
      integer :: threads, k
      m = int(t%m, c_int)
      mh = int(t%mh, c_int)
      nj = int(t%nj, c_int)
      freqs = int(t%freqs, c_int)
      call c_f_pointer(t%column_memory, t%column_real, [2*t%mh, t%nj])
      call c_f_pointer(t%column_memory, t%column_flat, [2*t%mh*t%nj])
      call c_f_pointer(t%column_memory, t%columns, [t%mh, t%nj])
      t%columns_forward = fftw_plan_many_dft_r2c(1_c_int, [m], nj, t%column_real, [2*mh], 1_c_int, 2*mh, &
         t%columns, [mh], 1_c_int, mh, flags)
      t%columns_backward = fftw_plan_many_dft_c2r(1_c_int, [m], nj, t%columns, [mh], 1_c_int, mh, &
         t%column_real, [2*mh], 1_c_int, 2*mh, flags)
      if (t%freqs > 0) then
         t%rows_forward = fftw_plan_many_dft(1_c_int, [m], freqs, t%rows, [m], 1_c_int, m, t%rows, [m], &
            1_c_int, m, FFTW_FORWARD, flags)
         t%rows_backward = fftw_plan_many_dft(1_c_int, [m], freqs, t%rows, [m], 1_c_int, m, t%rows, [m], &
            1_c_int, m, FFTW_BACKWARD, flags)
      end if
      threads = 1
      !$ threads = omp_get_max_threads()
      allocate(t%line_memory(0:threads - 1))
      do k = 0, threads - 1
         t%line_memory(k) = fftw_alloc_complex(int(t%m, c_size_t)*ROW_BLOCK)
      end do
      call c_f_pointer(t%line_memory(0), lines, [t%m, ROW_BLOCK])
      t%block_forward = fftw_plan_many_dft(1_c_int, [m], int(ROW_BLOCK, c_int), lines, [m], 1_c_int, m, lines, [m], &
         1_c_int, m, FFTW_FORWARD, flags)
      t%block_backward = fftw_plan_many_dft(1_c_int, [m], int(ROW_BLOCK, c_int), lines, [m], 1_c_int, m, lines, &
         [m], 1_c_int, m, FFTW_BACKWARD, flags)
      if (.not. t%on_node) then
         t%to_rows = fftw_mpi_plan_many_transpose(int(t%np, c_intptr_t), int(t%mh, c_intptr_t), 2_c_intptr_t, &
            int(t%block_columns, c_intptr_t), FFTW_MPI_DEFAULT_BLOCK, t%column_flat, t%row_flat, t%comm%MPI_VAL, flags)
         t%to_columns = fftw_mpi_plan_many_transpose(int(t%mh, c_intptr_t), int(t%np, c_intptr_t), 2_c_intptr_t, &
            FFTW_MPI_DEFAULT_BLOCK, int(t%block_columns, c_intptr_t), t%row_flat, t%column_flat, t%comm%MPI_VAL, flags)
      end if
      if (.not. (c_associated(t%columns_forward) .and. c_associated(t%columns_backward) .and. (t%on_node .or. &
         (c_associated(t%to_rows) .and. c_associated(t%to_columns))) .and. c_associated(t%block_forward) .and. &
         c_associated(t%block_backward) .and. (t%freqs == 0 .or. &
         (c_associated(t%rows_forward) .and. c_associated(t%rows_backward))))) &
         call set_error(status, STATUS_NUMERICAL, "FFTW made no plan for the "//int_str(t%m)//" x "// &
         int_str(t%m)//" grid")
   end subroutine make_plans

   !> The float32 views of the same memory and their plans (fftwf, fftwf_mpi).
   subroutine make_single_plans(t, flags, status)
      type(slab_transform), intent(inout) :: t
      integer(c_int), intent(in) :: flags
      type(status_type), intent(inout) :: status
      integer(c_int) :: m, mh, nj, freqs
      complex(c_float_complex), pointer :: lines32(:, :)
      m = int(t%m, c_int)
      mh = int(t%mh, c_int)
      nj = int(t%nj, c_int)
      freqs = int(t%freqs, c_int)
      call c_f_pointer(t%column_memory, t%column32_real, [2*t%mh, t%nj])
      call c_f_pointer(t%column_memory, t%column32_flat, [2*t%mh*t%nj])
      call c_f_pointer(t%column_memory, t%columns32, [t%mh, t%nj])
      t%columns_forward32 = fftwf_plan_many_dft_r2c(1_c_int, [m], nj, t%column32_real, [2*mh], 1_c_int, &
         2*mh, t%columns32, [mh], 1_c_int, mh, flags)
      t%columns_backward32 = fftwf_plan_many_dft_c2r(1_c_int, [m], nj, t%columns32, [mh], 1_c_int, mh, &
         t%column32_real, [2*mh], 1_c_int, 2*mh, flags)
      if (t%freqs > 0) then
         t%rows_forward32 = fftwf_plan_many_dft(1_c_int, [m], freqs, t%rows32, [m], 1_c_int, m, t%rows32, &
            [m], 1_c_int, m, FFTW_FORWARD, flags)
         t%rows_backward32 = fftwf_plan_many_dft(1_c_int, [m], freqs, t%rows32, [m], 1_c_int, m, t%rows32, &
            [m], 1_c_int, m, FFTW_BACKWARD, flags)
      end if
      call c_f_pointer(t%line_memory(0), lines32, [t%m, ROW_BLOCK])
      t%block_forward32 = fftwf_plan_many_dft(1_c_int, [m], int(ROW_BLOCK, c_int), lines32, [m], 1_c_int, m, &
         lines32, [m], 1_c_int, m, FFTW_FORWARD, flags)
      t%block_backward32 = fftwf_plan_many_dft(1_c_int, [m], int(ROW_BLOCK, c_int), lines32, [m], 1_c_int, m, &
         lines32, [m], 1_c_int, m, FFTW_BACKWARD, flags)
      if (.not. t%on_node) then
         t%to_rows32 = fftwf_mpi_plan_many_transpose(int(t%np, c_intptr_t), int(t%mh, c_intptr_t), &
            2_c_intptr_t, int(t%block_columns, c_intptr_t), FFTW_MPI_DEFAULT_BLOCK, t%column32_flat, &
            t%row32_flat, t%comm%MPI_VAL, flags)
         t%to_columns32 = fftwf_mpi_plan_many_transpose(int(t%mh, c_intptr_t), int(t%np, c_intptr_t), &
            2_c_intptr_t, FFTW_MPI_DEFAULT_BLOCK, int(t%block_columns, c_intptr_t), t%row32_flat, &
            t%column32_flat, t%comm%MPI_VAL, flags)
      end if
      if (.not. (c_associated(t%columns_forward32) .and. c_associated(t%columns_backward32) .and. (t%on_node .or. &
         (c_associated(t%to_rows32) .and. c_associated(t%to_columns32))) .and. c_associated(t%block_forward32) .and. &
         c_associated(t%block_backward32) .and. (t%freqs == 0 .or. &
         (c_associated(t%rows_forward32) .and. c_associated(t%rows_backward32))))) &
         call set_error(status, STATUS_NUMERICAL, "FFTW made no float32 plan for the "//int_str(t%m)//" x "// &
         int_str(t%m)//" grid")
   end subroutine make_single_plans

   !> The row memory (t%row_values_count complex values, FFTW's alignment, so that the
   !> plans made on the first apply to any) and its double and float32 views.
   subroutine allocate_rows(t)
      type(slab_transform), intent(inout) :: t
      t%row_memory = fftw_alloc_complex(t%row_values_count)
      call c_f_pointer(t%row_memory, t%rows, [t%m, max(t%freqs, 1)])
      call c_f_pointer(t%row_memory, t%row_values, [t%m*max(t%freqs, 1)])
      call c_f_pointer(t%row_memory, t%row_flat, [2*t%m*max(t%freqs, 1)])
      call c_f_pointer(t%row_memory, t%rows32, [t%m, max(t%freqs, 1)])
      call c_f_pointer(t%row_memory, t%row32_values, [t%m*max(t%freqs, 1)])
      call c_f_pointer(t%row_memory, t%row32_flat, [2*t%m*max(t%freqs, 1)])
   end subroutine allocate_rows

   !> The row memory freed when every rank is on one node, where slab_convolve reads its
   !> rows from the shared columns (an m x freqs complex array: 32 bytes a pixel of the
   !> free surface's grid over the ranks, 8 on the periodic cell); slab_forward allocates
   !> it again when called. Kept on several nodes: the transposes need it.
   subroutine slab_release_rows(t)
      type(slab_transform), intent(inout) :: t
      if (.not. (t%on_node .and. c_associated(t%row_memory))) return
      call fftw_free(t%row_memory)
      t%row_memory = c_null_ptr
      nullify(t%rows, t%row_values, t%row_flat, t%rows32, t%row32_values, t%row32_flat)
   end subroutine slab_release_rows

   subroutine slab_free(t)
      type(slab_transform), intent(inout) :: t
      integer :: k
      type(c_ptr) :: plans(8)
      plans = [t%columns_forward, t%columns_backward, t%rows_forward, t%rows_backward, t%to_rows, t%to_columns, &
         t%block_forward, t%block_backward]
      do k = 1, size(plans)
         if (c_associated(plans(k))) call fftw_destroy_plan(plans(k))
      end do
      plans = [t%columns_forward32, t%columns_backward32, t%rows_forward32, t%rows_backward32, t%to_rows32, &
         t%to_columns32, t%block_forward32, t%block_backward32]
      do k = 1, size(plans)
         if (c_associated(plans(k))) call fftwf_destroy_plan(plans(k))
      end do
      if (allocated(t%line_memory)) then
         do k = 0, size(t%line_memory) - 1
            if (c_associated(t%line_memory(k))) call fftw_free(t%line_memory(k))
         end do
      end if
      if (t%window /= MPI_WIN_NULL) then
         call MPI_Win_unlock_all(t%window)
         call MPI_Win_free(t%window)
      else if (c_associated(t%column_memory)) then
         call fftw_free(t%column_memory)
      end if
      if (c_associated(t%row_memory)) call fftw_free(t%row_memory)
      t = slab_transform()
   end subroutine slab_free

   !> The field f (np, nj; this rank's columns) zero-padded into the columns and
   !> transformed: its spectrum in t%rows. Collective.
   subroutine slab_forward_field(t, f)
      type(slab_transform), intent(inout) :: t
      real(dp), intent(in) :: f(:, :)
      call fill_columns(t, f, .true.)
      call slab_forward(t, PAD_ZEROS)
   end subroutine slab_forward_field

   !> The columns as they stand in t%column_real (m values each) transformed, the rows
   !> extended by `rows` (PAD_ZEROS, EXTEND_EVEN or EXTEND_ODD): the spectrum in t%rows.
   !> Collective.
   subroutine slab_forward(t, rows)
      type(slab_transform), intent(inout) :: t
      integer, intent(in) :: rows
      real(dp) :: t0, t1
      if (.not. c_associated(t%row_memory)) call allocate_rows(t)
      call column_transforms(t, .true., forward=.true.)
      call transpose_slab(t, .true., to_rows=.true., packed=.true.)
      call wall_clock(t0)
      call expand_rows(t, rows)
      if (allocated(t%natural)) call reorder_rows(t, .true.)
      if (t%freqs > 0) call fftw_execute_dft(t%rows_forward, t%rows, t%rows)
      call wall_clock(t1)
      t%transform_seconds = t%transform_seconds + (t1 - t0)
   end subroutine slab_forward

   !> The spectrum in t%rows transformed back: out (np, nj), this rank's columns, not
   !> normalised (FFTW's transforms). Collective.
   subroutine slab_backward(t, out)
      type(slab_transform), intent(inout) :: t
      real(dp), intent(out) :: out(:, :)
      real(dp) :: t0, t1
      call wall_clock(t0)
      if (t%freqs > 0) call fftw_execute_dft(t%rows_backward, t%rows, t%rows)
      if (allocated(t%natural)) call reorder_rows(t, .false.)
      call compress_rows(t)
      call wall_clock(t1)
      t%transform_seconds = t%transform_seconds + (t1 - t0)
      call transpose_slab(t, .true., to_rows=.false., packed=.true.)
      call column_transforms(t, .true., forward=.false.)
      call crop_columns(t, .true., out)
   end subroutine slab_backward

   !> out = factor K * f on this rank's columns (np, nj), K the real spectrum `kernel`
   !> (m/2 + 1, freqs: ky = 0 .. m/2, the kernel even in ky; over m^2 for FFTW's
   !> unnormalised transforms) on this rank's frequencies:
   !> slab_forward_field, the multiplication and slab_backward with the row step in one
   !> pass (module header). Not for a slab in another order (slab_permute). Collective.
   subroutine slab_convolve(t, f, kernel, factor, out)
      type(slab_transform), intent(inout) :: t
      real(dp), intent(in) :: f(:, :), kernel(:, :), factor
      real(dp), intent(out) :: out(:, :)
      call fill_columns(t, f, .true.)
      call column_transforms(t, .true., forward=.true.)
      call transpose_slab(t, .true., to_rows=.true., packed=.not. t%on_node)
      call rows_convolve(t, factor, kernel=kernel)
      call transpose_slab(t, .true., to_rows=.false., packed=.not. t%on_node)
      call column_transforms(t, .true., forward=.false.)
      call crop_columns(t, .true., out)
   end subroutine slab_convolve

   !> slab_convolve in float32 (the float32 plans, `kernel32`), into out (double) or out32;
   !> or a float32 field replaced by its float32 result (`in_place32`, instead of f and
   !> out). Collective.
   subroutine slab_convolve_single(t, f, kernel32, factor, out, out32, in_place32)
      type(slab_transform), intent(inout) :: t
      real(dp), intent(in), optional :: f(:, :)
      real(dp), intent(in) :: factor
      real(sp), intent(in) :: kernel32(:, :)
      real(dp), intent(out), optional :: out(:, :)
      real(sp), intent(out), optional :: out32(:, :)
      real(sp), intent(inout), optional :: in_place32(:, :)
      if (present(in_place32)) then
         call fill_columns(t, double=.false., f32=in_place32)
      else
         call fill_columns(t, f, .false.)
      end if
      call column_transforms(t, .false., forward=.true.)
      call transpose_slab(t, .false., to_rows=.true., packed=.not. t%on_node)
      call rows_convolve(t, factor, kernel32=kernel32)
      call transpose_slab(t, .false., to_rows=.false., packed=.not. t%on_node)
      call column_transforms(t, .false., forward=.false.)
      if (present(in_place32)) then
         call crop_columns(t, .false., out32=in_place32)
      else
         call crop_columns(t, .false., out, out32)
      end if
   end subroutine slab_convolve_single

   !> f (np, nj) into this rank's columns, zero-padded to m: in double or (`double` false)
   !> rounded to float32; or f32, in float32 as it is. Timed.
   subroutine fill_columns(t, f, double, f32)
      type(slab_transform), intent(inout) :: t
      real(dp), intent(in), optional :: f(:, :)
      logical, intent(in) :: double
      real(sp), intent(in), optional :: f32(:, :)
      integer :: j
      real(dp) :: t0, t1
      call wall_clock(t0)
      !$omp parallel do
      do j = 1, t%nj
         if (present(f32)) then
            t%column32_real(1:t%np, j) = f32(:, j)
            t%column32_real(t%np + 1:, j) = 0
         else if (double) then
            t%column_real(1:t%np, j) = f(:, j)
            t%column_real(t%np + 1:, j) = 0
         else
            t%column32_real(1:t%np, j) = real(f(:, j), sp)
            t%column32_real(t%np + 1:, j) = 0
         end if
      end do
      call wall_clock(t1)
      t%transform_seconds = t%transform_seconds + (t1 - t0)
   end subroutine fill_columns

   !> This rank's columns, cropped to np, into out (double) or out32, from the double or
   !> (`double` false) the float32 view.
   subroutine crop_columns(t, double, out, out32)
      type(slab_transform), intent(inout) :: t
      logical, intent(in) :: double
      real(dp), intent(out), optional :: out(:, :)
      real(sp), intent(out), optional :: out32(:, :)
      integer :: j
      real(dp) :: t0, t1
      call wall_clock(t0)
      !$omp parallel do
      do j = 1, t%nj
         if (present(out32)) then
            out32(:, j) = t%column32_real(1:t%np, j)
         else if (double) then
            out(:, j) = t%column_real(1:t%np, j)
         else
            out(:, j) = real(t%column32_real(1:t%np, j), dp)
         end if
      end do
      call wall_clock(t1)
      t%transform_seconds = t%transform_seconds + (t1 - t0)
   end subroutine crop_columns

   !> The r2c (`forward`) or c2r transforms down this rank's columns as they stand in the
   !> column memory, in double or (`double` false) float32. Timed.
   subroutine column_transforms(t, double, forward)
      type(slab_transform), intent(inout) :: t
      logical, intent(in) :: double, forward
      real(dp) :: t0, t1
      call wall_clock(t0)
      if (double .and. forward) then
         call fftw_execute_dft_r2c(t%columns_forward, t%column_real, t%columns)
      else if (double) then
         call fftw_execute_dft_c2r(t%columns_backward, t%columns, t%column_real)
      else if (forward) then
         call fftwf_execute_dft_r2c(t%columns_forward32, t%column32_real, t%columns32)
      else
         call fftwf_execute_dft_c2r(t%columns_backward32, t%columns32, t%column32_real)
      end if
      call wall_clock(t1)
      t%transform_seconds = t%transform_seconds + (t1 - t0)
   end subroutine column_transforms

   !> The transpose between this rank's columns and its frequencies' packed rows (np
   !> values each; `to_rows`: towards them), FFTW-MPI's or through the node's memory; with
   !> `packed` false on one node only the barrier after which every rank's writes to the
   !> columns are seen (the one-pass row step reads and writes them there). Timed as
   !> communication. Collective.
   subroutine transpose_slab(t, double, to_rows, packed)
      type(slab_transform), intent(inout) :: t
      logical, intent(in) :: double, to_rows, packed
      real(dp) :: t0, t1
      call wall_clock(t0)
      if (t%on_node .and. .not. packed) then
         call node_barrier(t)
      else if (t%on_node) then
         call node_transpose(t, double, to_rows)
      else if (double .and. to_rows) then
         call fftw_mpi_execute_r2r(t%to_rows, t%column_flat, t%row_flat)
      else if (double) then
         call fftw_mpi_execute_r2r(t%to_columns, t%row_flat, t%column_flat)
      else if (to_rows) then
         call fftwf_mpi_execute_r2r(t%to_rows32, t%column32_flat, t%row32_flat)
      else
         call fftwf_mpi_execute_r2r(t%to_columns32, t%row32_flat, t%column32_flat)
      end if
      call wall_clock(t1)
      t%communication_seconds = t%communication_seconds + (t1 - t0)
   end subroutine transpose_slab

   !> The row step of a convolution in one pass (module header): in blocks of ROW_BLOCK of
   !> this rank's frequencies, the rows zero-padded to m in the thread's buffer, transformed
   !> forward, multiplied by factor kernel(|ky|, k) (or, in float32, factor kernel32),
   !> transformed back, and their first np values stored back. The rows are read from and
   !> written to the packed rows of the transpose, or, on one node, every rank's columns in
   !> the shared window, as the serial convolution reads its spectrum: the transpose is
   !> this copy. Timed.
   subroutine rows_convolve(t, factor, kernel, kernel32)
      type(slab_transform), intent(inout) :: t
      real(dp), intent(in) :: factor
      real(dp), intent(in), optional :: kernel(:, :)
      real(sp), intent(in), optional :: kernel32(:, :)
      complex(c_double_complex), pointer :: lines(:, :)
      complex(c_float_complex), pointer :: lines32(:, :)
      integer :: thread, kb, k0, nb, l, kh
      real(dp) :: t0, t1
      call wall_clock(t0)
      kh = t%m/2
      !$omp parallel num_threads(size(t%line_memory)) private(thread, lines, lines32, kb, k0, nb, l)
      thread = 0
      !$ thread = omp_get_thread_num()
      call c_f_pointer(t%line_memory(thread), lines, [t%m, ROW_BLOCK])
      call c_f_pointer(t%line_memory(thread), lines32, [t%m, ROW_BLOCK])
      !$omp do schedule(static)
      do kb = 1, (t%freqs + ROW_BLOCK - 1)/ROW_BLOCK
         k0 = (kb - 1)*ROW_BLOCK
         nb = min(ROW_BLOCK, t%freqs - k0)
         call move_rows(t, k0, nb, present(kernel), lines, lines32, to_lines=.true.)
         if (present(kernel)) then
            call fftw_execute_dft(t%block_forward, lines, lines)
            do l = 1, nb
               lines(1:kh + 1, l) = lines(1:kh + 1, l)*(factor*kernel(:, k0 + l))
               lines(kh + 2:, l) = lines(kh + 2:, l)*(factor*kernel(t%m - kh:2:-1, k0 + l))
            end do
            call fftw_execute_dft(t%block_backward, lines, lines)
         else
            call fftwf_execute_dft(t%block_forward32, lines32, lines32)
            do l = 1, nb
               lines32(1:kh + 1, l) = lines32(1:kh + 1, l)*(real(factor, sp)*kernel32(:, k0 + l))
               lines32(kh + 2:, l) = lines32(kh + 2:, l)*(real(factor, sp)*kernel32(t%m - kh:2:-1, k0 + l))
            end do
            call fftwf_execute_dft(t%block_backward32, lines32, lines32)
         end if
         call move_rows(t, k0, nb, present(kernel), lines, lines32, to_lines=.false.)
      end do
      !$omp end do
      !$omp end parallel
      call wall_clock(t1)
      t%transform_seconds = t%transform_seconds + (t1 - t0)
   end subroutine rows_convolve

   !> Rows k0 + 1 .. k0 + nb of this rank's frequencies into the block `lines` (double) or
   !> `lines32`, zero-padded to m (the block's unused rows zero), from the packed rows or
   !> on one node every rank's columns; or (`to_lines` false) their first np values back.
   subroutine move_rows(t, k0, nb, double, lines, lines32, to_lines)
      type(slab_transform), intent(inout) :: t
      integer, intent(in) :: k0, nb
      logical, intent(in) :: double, to_lines
      complex(c_double_complex), intent(inout) :: lines(:, :)
      complex(c_float_complex), intent(inout) :: lines32(:, :)
      integer :: l, r, j, np, f0
      np = t%np
      f0 = t%freq_start + k0
      if (t%on_node) then
         do r = 0, size(t%peer) - 1
            associate(p => t%peer(r))
               do j = 1, size(p%z, 2)
                  if (double .and. to_lines) then
                     lines(p%first + j, 1:nb) = p%z(f0 + 1:f0 + nb, j)
                  else if (double) then
                     p%z(f0 + 1:f0 + nb, j) = lines(p%first + j, 1:nb)
                  else if (to_lines) then
                     lines32(p%first + j, 1:nb) = p%c(f0 + 1:f0 + nb, j)
                  else
                     p%c(f0 + 1:f0 + nb, j) = lines32(p%first + j, 1:nb)
                  end if
               end do
            end associate
         end do
      else
         do l = 1, nb
            if (double .and. to_lines) then
               lines(1:np, l) = t%row_values((k0 + l - 1)*np + 1:(k0 + l)*np)
            else if (double) then
               t%row_values((k0 + l - 1)*np + 1:(k0 + l)*np) = lines(1:np, l)
            else if (to_lines) then
               lines32(1:np, l) = t%row32_values((k0 + l - 1)*np + 1:(k0 + l)*np)
            else
               t%row32_values((k0 + l - 1)*np + 1:(k0 + l)*np) = lines32(1:np, l)
            end if
         end do
      end if
      if (.not. to_lines) return
      if (double) then
         lines(np + 1:, 1:nb) = 0
         lines(:, nb + 1:) = 0
      else
         lines32(np + 1:, 1:nb) = 0
         lines32(:, nb + 1:) = 0
      end if
   end subroutine move_rows

   !> The shared window of every rank's columns (module header) when every rank of t%comm
   !> is on one node and FEMCOD_MPI_TRANSPOSES is not `fftw-mpi` (which keeps FFTW-MPI's
   !> transposes, as on several nodes: the tests run both): this rank's part, its mh x nj
   !> half spectra, is its column memory, and every rank's part is mapped (t%peer).
   !> Collective.
   subroutine node_window_setup(t)
      type(slab_transform), intent(inout) :: t
      type(c_ptr) :: base
      integer(MPI_ADDRESS_KIND) :: bytes
      integer :: ranks, r, unit, count
      t%on_node = shared_transposes(t%comm)
      if (.not. t%on_node) return
      call MPI_Comm_size(t%comm, ranks)
      ! One byte units, and ALIGNMENT more: each part is used from its first aligned byte,
      ! as FFTW's own allocations are (a window's part may start at any 8 bytes, and FFTW
      ! plans other, slower, codelets for unaligned memory).
      unit = 1
      bytes = int(storage_size((1.0_c_double, 0.0_c_double))/8, MPI_ADDRESS_KIND)* &
         max(int(t%mh, MPI_ADDRESS_KIND)*int(t%nj, MPI_ADDRESS_KIND), 1_MPI_ADDRESS_KIND) + ALIGNMENT
      call MPI_Win_allocate_shared(bytes, unit, MPI_INFO_NULL, t%comm, base, t%window)
      call MPI_Win_lock_all(MPI_MODE_NOCHECK, t%window)
      t%column_memory = aligned(base)
      allocate(t%peer(0:ranks - 1))
      do r = 0, ranks - 1
         t%peer(r)%first = min(r*t%block_columns, t%np)
         count = max(0, min(t%block_columns, t%np - r*t%block_columns))
         call MPI_Win_shared_query(t%window, r, bytes, unit, base)
         call c_f_pointer(aligned(base), t%peer(r)%z, [t%mh, count])
         call c_f_pointer(aligned(base), t%peer(r)%c, [t%mh, count])
      end do
   contains
      !> The first address at or after `address` that is a multiple of ALIGNMENT (the
      !> ranks map the window at page boundaries, so every rank finds the same byte).
      type(c_ptr) function aligned(address)
         type(c_ptr), intent(in) :: address
         integer(c_intptr_t) :: a
         a = transfer(address, a)
         a = a + modulo(-a, int(ALIGNMENT, c_intptr_t))
         aligned = transfer(a, aligned)
      end function aligned
   end subroutine node_window_setup

   !> True on every rank when the slab transforms of `comm` go through the node's shared
   !> memory: every rank on one node, and FEMCOD_MPI_TRANSPOSES not `fftw-mpi`.
   !> Collective.
   logical function shared_transposes(comm)
      type(MPI_Comm), intent(in) :: comm
      character(len=16) :: choice
      integer :: length
      call get_environment_variable(TRANSPOSES_VARIABLE, choice, length)
      shared_transposes = .not. (length > 0 .and. choice == "fftw-mpi")
      if (shared_transposes) shared_transposes = on_one_node(comm)
   end function shared_transposes

   !> True on every rank when all the ranks of `comm` share one node's memory
   !> (MPI_COMM_TYPE_SHARED). Collective.
   logical function on_one_node(comm)
      type(MPI_Comm), intent(in) :: comm
      type(MPI_Comm) :: node
      integer :: ranks, rank, node_ranks
      call MPI_Comm_size(comm, ranks)
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, node)
      call MPI_Comm_size(node, node_ranks)
      call MPI_Comm_free(node)
      on_one_node = node_ranks == ranks
   end function on_one_node

   !> The transpose through the node's shared memory, between barriers (every rank's
   !> stores seen before any rank reads, and no rank writes anew, two forward transforms
   !> in a row as the shear operator's, before every rank has read): `to_rows`
   !> (slab_forward's), this rank's frequencies of every rank's columns into the packed
   !> rows (np values a frequency); else (slab_backward's) the packed rows back into
   !> every rank's columns. In blocks of columns that stay in cache; `double`: the double
   !> or the float32 views. Collective.
   subroutine node_transpose(t, double, to_rows)
      type(slab_transform), intent(inout) :: t
      logical, intent(in) :: double, to_rows
      integer, parameter :: COLUMNS_AT_A_TIME = 256
      integer :: r, jb, je, l, f0, np
      call node_barrier(t)
      f0 = t%freq_start
      np = t%np
      do r = 0, size(t%peer) - 1
         associate(p => t%peer(r))
            do jb = 1, size(p%z, 2), COLUMNS_AT_A_TIME
               je = min(jb + COLUMNS_AT_A_TIME - 1, size(p%z, 2))
               !$omp parallel do
               do l = 1, t%freqs
                  if (double .and. to_rows) then
                     t%row_values((l - 1)*np + p%first + jb:(l - 1)*np + p%first + je) = p%z(f0 + l, jb:je)
                  else if (double) then
                     p%z(f0 + l, jb:je) = t%row_values((l - 1)*np + p%first + jb:(l - 1)*np + p%first + je)
                  else if (to_rows) then
                     t%row32_values((l - 1)*np + p%first + jb:(l - 1)*np + p%first + je) = p%c(f0 + l, jb:je)
                  else
                     p%c(f0 + l, jb:je) = t%row32_values((l - 1)*np + p%first + jb:(l - 1)*np + p%first + je)
                  end if
               end do
            end do
         end associate
      end do
      call node_barrier(t)
   end subroutine node_transpose

   !> Every rank's stores to the window seen by every rank (MPI's unified memory model:
   !> sync, barrier, sync).
   subroutine node_barrier(t)
      type(slab_transform), intent(inout) :: t
      call MPI_Win_sync(t%window)
      call MPI_Barrier(t%comm)
      call MPI_Win_sync(t%window)
   end subroutine node_barrier

   !> The transposed rows (np values per frequency, packed) spread in place to rows of m:
   !> zero-padded, or evenly (x(m - q) = x(q)) or oddly (x(m - q) = -x(q)) extended, with
   !> x(np) = 0. From the last row down, each from its end: nothing is overwritten
   !> before it is read.
   subroutine expand_rows(t, how)
      type(slab_transform), intent(inout) :: t
      integer, intent(in) :: how
      integer :: k, i, np, m
      np = t%np
      m = t%m
      ! Rows of np are rows of m already on the periodic cell (m = np).
      if (m == np) return
      do k = t%freqs, 1, -1
         do i = np, 1, -1
            t%row_values((k - 1)*m + i) = t%row_values((k - 1)*np + i)
         end do
         t%row_values((k - 1)*m + np + 1) = 0
         if (how == PAD_ZEROS) then
            t%row_values((k - 1)*m + np + 2:k*m) = 0
         else
            do i = np + 2, m
               t%row_values((k - 1)*m + i) = how*t%row_values((k - 1)*m + m - i + 2)
            end do
         end if
      end do
   end subroutine expand_rows

   !> The order of the ranks' columns (slab_transform's natural): `natural` (1 .. m, each
   !> once) for a transform whose rows are m long and not extended (slab_setup's np = m).
   subroutine slab_permute(t, natural)
      type(slab_transform), intent(inout) :: t
      integer, intent(in) :: natural(:)
      t%natural = natural
   end subroutine slab_permute

   !> Each transposed row put in the grid's order (`to_natural`) or back in the ranks'.
   subroutine reorder_rows(t, to_natural)
      type(slab_transform), intent(inout) :: t
      logical, intent(in) :: to_natural
      complex(dp), allocatable :: line(:)
      integer :: k, p
      !$omp parallel private(line, p)
      allocate(line(t%m))
      !$omp do
      do k = 1, t%freqs
         if (to_natural) then
            do p = 1, t%m
               line(t%natural(p)) = t%rows(p, k)
            end do
         else
            do p = 1, t%m
               line(p) = t%rows(t%natural(p), k)
            end do
         end if
         t%rows(:, k) = line
      end do
      !$omp end do
      !$omp end parallel
   end subroutine reorder_rows

   !> The first np values of each row of m packed again for the transpose back (from the
   !> first row up: nothing is overwritten before it is read).
   subroutine compress_rows(t)
      type(slab_transform), intent(inout) :: t
      integer :: k, i, np, m
      np = t%np
      m = t%m
      if (m == np) return
      do k = 1, t%freqs
         do i = 1, np
            t%row_values((k - 1)*np + i) = t%row_values((k - 1)*m + i)
         end do
      end do
   end subroutine compress_rows

   !> The backward DFT of the NP x NP field whose columns j0 + 1 .. j0 + nj this rank
   !> holds (every rank's block_columns, but the last ranks'): the buffers, then
   !> dft%input filled by the caller, slab_dft_backward, dft%output read. An error when
   !> FFTW-MPI would split the columns otherwise or makes no plan. Collective over `comm`.
   subroutine slab_dft_setup(dft, comm, np, j0, nj, block_columns, status)
      type(slab_dft), intent(inout) :: dft
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, j0, nj, block_columns
      type(status_type), intent(inout) :: status
      integer(c_intptr_t) :: alloc, local_n0, start, n(2)
      n = [integer(c_intptr_t) :: np, np]
      alloc = fftw_mpi_local_size_many(2_c_int, n, 1_c_intptr_t, int(block_columns, c_intptr_t), comm%MPI_VAL, &
         local_n0, start)
      if (int(local_n0) /= nj .or. int(start) /= j0) then
         call set_error(status, STATUS_NUMERICAL, "FFTW-MPI splits the generated surface otherwise than the solver")
         return
      end if
      dft%input_memory = fftw_alloc_complex(int(max(alloc, int(np, c_intptr_t)*nj, 1_c_intptr_t), c_size_t))
      dft%output_memory = fftw_alloc_complex(int(max(alloc, int(np, c_intptr_t)*nj, 1_c_intptr_t), c_size_t))
      call c_f_pointer(dft%input_memory, dft%input, [np, nj])
      call c_f_pointer(dft%output_memory, dft%output, [np, nj])
      dft%plan = fftw_mpi_plan_many_dft(2_c_int, n, 1_c_intptr_t, int(block_columns, c_intptr_t), &
         FFTW_MPI_DEFAULT_BLOCK, dft%input, dft%output, comm%MPI_VAL, FFTW_BACKWARD, FFTW_ESTIMATE)
      if (.not. c_associated(dft%plan)) &
         call set_error(status, STATUS_NUMERICAL, "FFTW-MPI made no plan for the "//int_str(np)//"^2 surface")
   end subroutine slab_dft_setup

   !> dft%output = the backward DFT of dft%input (unnormalised, as FFTW's).
   subroutine slab_dft_backward(dft)
      type(slab_dft), intent(inout) :: dft
      ! An MPI plan's new-array execute is FFTW-MPI's (the serial one does nothing).
      call fftw_mpi_execute_dft(dft%plan, dft%input, dft%output)
   end subroutine slab_dft_backward

   subroutine slab_dft_free(dft)
      type(slab_dft), intent(inout) :: dft
      if (c_associated(dft%plan)) call fftw_destroy_plan(dft%plan)
      if (c_associated(dft%input_memory)) call fftw_free(dft%input_memory)
      if (c_associated(dft%output_memory)) call fftw_free(dft%output_memory)
      dft = slab_dft()
   end subroutine slab_dft_free
end module femcod_mpi_slab_transform
