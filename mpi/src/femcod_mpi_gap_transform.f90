!> The gap-variable iteration's transform grid (solvers/femcod_gap_cg) on MPI ranks: the
!> compliance C = c (I * .) + s and the stiffness K = C^-1, diagonal in Fourier space, on
!> the whole M x M transform grid (M = 2 NP zero-padded on the free surface, NP on the
!> periodic cell), whose every point is an unknown of the iteration.
!>
!> Layout: each rank holds the transform grid's columns that belong with its own grid
!> columns: its nj pixel columns j0 + 1 .. j0 + nj, and on the free surface besides the
!> nj padding columns NP + j0 + 1 .. NP + j0 + nj. Its field is (M, 2 nj) (free) or
!> (NP, nj) (periodic), pixel columns first, so that its pixels are the field's first
!> NP rows of its first nj columns, as the elastic operator says. FFTW-MPI's transpose
!> moves contiguous blocks of columns; in this order rank r's columns are the block
!> 2 r b .. 2 r b + 2 nj - 1 (b the solver's columns per rank), so the transposes move
!> the columns in that permuted order, and each rank puts its rows back in the natural
!> order (a local copy) before the transforms along them.
!>
!> Steps: r2c of length M down this rank's columns, transpose to this rank's
!> frequencies, c2c along the rows (natural order), the spectrum, back the same way.
!> The spectra are made from the distributed operator's kernel spectrum (the Love
!> table's, or the periodic cell's in closed form), on the same frequencies.
!>
!> No I/O and no stop.
module femcod_mpi_gap_transform
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_double, c_double_complex, c_intptr_t, c_int, &
      c_f_pointer, c_associated, c_size_t
   use mpi_f08
   use femcod_fftw_mpi, only: fftw_mpi_local_size_many_transposed, fftw_mpi_plan_many_transpose, fftw_mpi_execute_r2r, &
      fftw_plan_many_dft_r2c, fftw_plan_many_dft_c2r, fftw_plan_many_dft, fftw_execute_dft_r2c, fftw_execute_dft_c2r, &
      fftw_execute_dft, fftw_alloc_complex, fftw_free, fftw_destroy_plan, FFTW_ESTIMATE, FFTW_FORWARD, &
      FFTW_BACKWARD, FFTW_MPI_DEFAULT_BLOCK
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_elastic_operator, only: SPECTRUM_COMPLIANCE
   use femcod_strings, only: int_str
   implicit none
   private
   public :: distributed_gap_transform, gap_transform_setup, gap_transform_apply, gap_transform_free

   !> One rank's part of the transform grid (module header).
   type :: distributed_gap_transform
      !> The transform length M, its half spectrum mh, the grid side np, this rank's
      !> field columns (2 nj or nj), its frequencies (first, number).
      integer :: m = 0, mh = 0, np = 0, columns = 0, freq_start = 0, freqs = 0
      !> natural(P): the transform grid column (1-based) at position P of the permuted order.
      integer, allocatable :: natural(:)
      type(c_ptr) :: column_memory = c_null_ptr, row_memory = c_null_ptr, line_memory = c_null_ptr
      real(c_double), pointer :: column_real(:, :) => null(), column_flat(:) => null(), row_flat(:) => null()
      complex(c_double_complex), pointer :: column_spectrum(:, :) => null(), rows(:, :) => null(), &
         lines(:, :) => null()
      type(c_ptr) :: down_forward = c_null_ptr, down_backward = c_null_ptr, along_forward = c_null_ptr, &
         along_backward = c_null_ptr, to_rows = c_null_ptr, to_columns = c_null_ptr
      !> The spectra on this rank's frequencies (m, freqs), divided by m^2.
      real(dp), allocatable :: compliance(:, :), stiffness(:, :)
      !> The smallest value of C's spectrum on this rank (nm/nN; the zero frequency of a
      !> periodic cell left out).
      real(dp) :: smallest = huge(1.0_dp)
   end type distributed_gap_transform

contains

   !> The transform grid for a grid of side np split as the solver's columns (first(r),
   !> count(r) for each rank r; `block` columns per rank), with the kernel's spectrum
   !> `kernel` (m, freqs; divided by m^2) on frequencies freq_start.. of the same
   !> transposes, the compliance c and the springs' s (nm/nN). Collective.
   subroutine gap_transform_setup(t, comm, np, first, count, block, periodic, kernel, freq_start, c, s, status)
      type(distributed_gap_transform), intent(inout) :: t
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, first(0:), count(0:), block, freq_start
      logical, intent(in) :: periodic
      real(dp), intent(in) :: kernel(:, :), c, s
      type(status_type), intent(inout) :: status
      integer(c_intptr_t) :: alloc, dims(2), local_columns, column_start, local_freqs, start
      integer :: rank, pad, total
      call MPI_Comm_rank(comm, rank)
      pad = merge(1, 2, periodic)
      t%np = np
      t%m = pad*np
      t%mh = t%m/2 + 1
      t%columns = pad*count(rank)
      total = t%m
      dims = [integer(c_intptr_t) :: total, t%mh]
      alloc = fftw_mpi_local_size_many_transposed(2_c_int, dims, 2_c_intptr_t, int(pad*block, c_intptr_t), &
         FFTW_MPI_DEFAULT_BLOCK, comm%MPI_VAL, local_columns, column_start, local_freqs, start)
      t%freqs = int(local_freqs)
      t%freq_start = int(start)
      if (int(local_columns) /= t%columns .or. int(column_start) /= pad*first(rank) .or. &
         t%freq_start /= freq_start .or. t%freqs /= size(kernel, 2) .or. size(kernel, 1) /= t%m) then
         call set_error(status, STATUS_NUMERICAL, "FFTW-MPI splits the transform grid otherwise than the "// &
            "solver: rank "//int_str(rank)//" has "//int_str(int(local_columns))//" columns from "// &
            int_str(int(column_start)))
         return
      end if
      call permutation(t, first, count, pad)
      t%column_memory = fftw_alloc_complex(int(max(alloc/2, int(t%mh, c_intptr_t)*t%columns, 1_c_intptr_t), c_size_t))
      t%row_memory = fftw_alloc_complex(int(max(alloc/2, int(t%m, c_intptr_t)*t%freqs, 1_c_intptr_t), c_size_t))
      t%line_memory = fftw_alloc_complex(int(max(int(t%m, c_intptr_t)*t%freqs, 1_c_intptr_t), c_size_t))
      call make_plans(t, comm, pad*block, status)
      if (status%code /= 0) return
      call make_spectra(t, kernel, c, s, periodic)
   end subroutine gap_transform_setup

   !> natural(P) for the permuted order: rank r's positions 2 r b + 1 .. hold its pixel
   !> columns, then its padding columns (module header; the identity on a periodic cell).
   pure subroutine permutation(t, first, count, pad)
      type(distributed_gap_transform), intent(inout) :: t
      integer, intent(in) :: first(0:), count(0:), pad
      integer :: r, k, position
      allocate(t%natural(t%m))
      position = 0
      do r = 0, size(count) - 1
         do k = 1, count(r)
            t%natural(position + k) = first(r) + k
         end do
         position = position + count(r)
         if (pad == 2) then
            do k = 1, count(r)
               t%natural(position + k) = t%np + first(r) + k
            end do
            position = position + count(r)
         end if
      end do
   end subroutine permutation

   !> The views of the memory and the plans: r2c / c2r of length m down this rank's
   !> columns, c2c of length m along its rows, FFTW-MPI's transposes (blocks of `block`
   !> columns).
   subroutine make_plans(t, comm, block, status)
      type(distributed_gap_transform), intent(inout) :: t
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: block
      type(status_type), intent(inout) :: status
      integer(c_int) :: m, mh, columns, freqs
      m = int(t%m, c_int)
      mh = int(t%mh, c_int)
      columns = int(t%columns, c_int)
      freqs = int(t%freqs, c_int)
      call c_f_pointer(t%column_memory, t%column_real, [2*t%mh, t%columns])
      call c_f_pointer(t%column_memory, t%column_flat, [2*t%mh*t%columns])
      call c_f_pointer(t%column_memory, t%column_spectrum, [t%mh, t%columns])
      call c_f_pointer(t%row_memory, t%rows, [t%m, max(t%freqs, 1)])
      call c_f_pointer(t%row_memory, t%row_flat, [2*t%m*max(t%freqs, 1)])
      call c_f_pointer(t%line_memory, t%lines, [t%m, max(t%freqs, 1)])
      t%down_forward = fftw_plan_many_dft_r2c(1_c_int, [m], columns, t%column_real, [2*mh], 1_c_int, 2*mh, &
         t%column_spectrum, [mh], 1_c_int, mh, FFTW_ESTIMATE)
      t%down_backward = fftw_plan_many_dft_c2r(1_c_int, [m], columns, t%column_spectrum, [mh], 1_c_int, mh, &
         t%column_real, [2*mh], 1_c_int, 2*mh, FFTW_ESTIMATE)
      if (t%freqs > 0) then
         t%along_forward = fftw_plan_many_dft(1_c_int, [m], freqs, t%lines, [m], 1_c_int, m, t%lines, [m], 1_c_int, &
            m, FFTW_FORWARD, FFTW_ESTIMATE)
         t%along_backward = fftw_plan_many_dft(1_c_int, [m], freqs, t%lines, [m], 1_c_int, m, t%lines, [m], 1_c_int, &
            m, FFTW_BACKWARD, FFTW_ESTIMATE)
      end if
      t%to_rows = fftw_mpi_plan_many_transpose(int(t%m, c_intptr_t), int(t%mh, c_intptr_t), 2_c_intptr_t, &
         int(block, c_intptr_t), FFTW_MPI_DEFAULT_BLOCK, t%column_flat, t%row_flat, comm%MPI_VAL, FFTW_ESTIMATE)
      t%to_columns = fftw_mpi_plan_many_transpose(int(t%mh, c_intptr_t), int(t%m, c_intptr_t), 2_c_intptr_t, &
         FFTW_MPI_DEFAULT_BLOCK, int(block, c_intptr_t), t%row_flat, t%column_flat, comm%MPI_VAL, FFTW_ESTIMATE)
      if (.not. (c_associated(t%down_forward) .and. c_associated(t%down_backward) .and. c_associated(t%to_rows) &
         .and. c_associated(t%to_columns) .and. (t%freqs == 0 .or. (c_associated(t%along_forward) .and. &
         c_associated(t%along_backward))))) call set_error(status, STATUS_NUMERICAL, "FFTW made no plan for the "// &
         int_str(t%m)//" x "//int_str(t%m)//" transform grid of the gap variables")
   end subroutine make_plans

   !> C = (c m^2 kernel + s)/m^2 and K = 1/(c m^2 kernel + s)/m^2 (kernel divided by m^2,
   !> as the serial femcod_convolution's gap_transform); on a periodic cell both 0 at zero
   !> frequency.
   pure subroutine make_spectra(t, kernel, c, s, periodic)
      type(distributed_gap_transform), intent(inout) :: t
      real(dp), intent(in) :: kernel(:, :), c, s
      logical, intent(in) :: periodic
      real(dp) :: m2
      logical :: zero
      integer :: i, k
      m2 = real(t%m, dp)**2
      allocate(t%compliance(t%m, t%freqs), t%stiffness(t%m, t%freqs))
      t%smallest = huge(1.0_dp)
      do k = 1, t%freqs
         do i = 1, t%m
            zero = periodic .and. t%freq_start + k == 1 .and. i == 1
            t%compliance(i, k) = c*(kernel(i, k)*m2) + s
            if (zero) then
               t%compliance(i, k) = 0
               t%stiffness(i, k) = 0
            else
               t%smallest = min(t%smallest, t%compliance(i, k))
               t%stiffness(i, k) = 1/t%compliance(i, k)/m2
               t%compliance(i, k) = t%compliance(i, k)/m2
            end if
         end do
      end do
   end subroutine make_spectra

   !> out = C in or K in (`which`) on this rank's field (m, columns). Collective.
   subroutine gap_transform_apply(t, which, in, out)
      type(distributed_gap_transform), intent(inout) :: t
      integer, intent(in) :: which
      real(dp), intent(in) :: in(:, :)
      real(dp), intent(out) :: out(:, :)
      integer :: j, k, p
      !$omp parallel do
      do j = 1, t%columns
         t%column_real(1:t%m, j) = in(:, j)
      end do
      call fftw_execute_dft_r2c(t%down_forward, t%column_real, t%column_spectrum)
      call fftw_mpi_execute_r2r(t%to_rows, t%column_flat, t%row_flat)
      if (t%freqs > 0) then
         !$omp parallel do private(p)
         do k = 1, t%freqs
            do p = 1, t%m
               t%lines(t%natural(p), k) = t%rows(p, k)
            end do
         end do
         call fftw_execute_dft(t%along_forward, t%lines, t%lines)
         if (which == SPECTRUM_COMPLIANCE) then
            !$omp parallel do
            do k = 1, t%freqs
               t%lines(:, k) = t%lines(:, k)*t%compliance(:, k)
            end do
         else
            !$omp parallel do
            do k = 1, t%freqs
               t%lines(:, k) = t%lines(:, k)*t%stiffness(:, k)
            end do
         end if
         call fftw_execute_dft(t%along_backward, t%lines, t%lines)
         !$omp parallel do private(p)
         do k = 1, t%freqs
            do p = 1, t%m
               t%rows(p, k) = t%lines(t%natural(p), k)
            end do
         end do
      end if
      call fftw_mpi_execute_r2r(t%to_columns, t%row_flat, t%column_flat)
      call fftw_execute_dft_c2r(t%down_backward, t%column_spectrum, t%column_real)
      !$omp parallel do
      do j = 1, t%columns
         out(:, j) = t%column_real(1:t%m, j)
      end do
   end subroutine gap_transform_apply

   subroutine gap_transform_free(t)
      type(distributed_gap_transform), intent(inout) :: t
      type(c_ptr) :: plans(4)
      integer :: k
      plans = [t%down_forward, t%down_backward, t%along_forward, t%along_backward]
      do k = 1, size(plans)
         if (c_associated(plans(k))) call fftw_destroy_plan(plans(k))
      end do
      if (c_associated(t%to_rows)) call fftw_destroy_plan(t%to_rows)
      if (c_associated(t%to_columns)) call fftw_destroy_plan(t%to_columns)
      if (c_associated(t%column_memory)) call fftw_free(t%column_memory)
      if (c_associated(t%row_memory)) call fftw_free(t%row_memory)
      if (c_associated(t%line_memory)) call fftw_free(t%line_memory)
      t = distributed_gap_transform()
   end subroutine gap_transform_free
end module femcod_mpi_gap_transform
