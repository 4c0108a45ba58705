!> The fixed-load solver (`--solver cg`, femcod_cg) on MPI ranks: the same complementarity
!> problem, method, stopping rule and residuals, with the NP x NP grid split in column slabs
!> across the ranks of a communicator.
!>
!> - The Love-kernel convolution on the zero-padded (2 NP)^2 grid, pruned as the serial
!>   one is (femcod_convolution): real-to-complex transforms of length 2 NP down this
!>   rank's columns (only NP of the 2 NP are not zero), FFTW-MPI's distributed transpose of
!>   the (NP + 1) x NP half spectrum, complex transforms of length 2 NP along the rows of
!>   this rank's frequencies, the kernel, and back the same way. Only the non-zero half is
!>   transformed and moved: the full FFTW-MPI r2c of the padded grid transforms and
!>   transposes twice as much, and hands the physical columns to half of the ranks. The
!>   kernel's spectrum is made the same way from the even extension of the Love table,
!>   each rank from its own columns. FFTW's threads within a rank.
!> - Sums and maxima by MPI_Allreduce; the preconditioner's 13-point stencil reads two
!>   columns of each neighbour (MPI_Sendrecv).
!> - The first load starts from a coarse solution on rank 0 (femcod_cg's own nested start
!>   at NP/f, f the smallest power of two with f^2 >= ranks, so that it needs no more memory
!>   than a rank's share): with up to 4 ranks the same start as the serial solver's.
!> - float32 transforms (FFTW's fftwf, the transposes fftwf_mpi) where the serial solver
!>   uses them: the search directions always, the forces' own displacements while the
!>   residual is above `single_until`; every switch and the final answer from a fresh
!>   double convolution.
!> - Every force the projection changes brings a fresh convolution (the serial solver adds
!>   up to `direct_corrections` of them from the Love table, which would be NP^2 values on
!>   every rank): more convolutions, the same answer (to the tolerance).
!>
!> No I/O and no stop: errors come back in a status, identical on every rank.
module femcod_mpi_cg
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_double, c_double_complex, c_float, c_float_complex, &
      c_intptr_t, c_int, c_f_pointer, c_associated, c_size_t
   use mpi_f08
   use femcod_fftw_mpi, only: fftw_mpi_local_size_many_transposed, fftw_mpi_plan_many_transpose, fftw_mpi_execute_r2r, &
      fftw_plan_many_dft_r2c, fftw_plan_many_dft_c2r, fftw_plan_many_dft, fftw_execute_dft_r2c, fftw_execute_dft_c2r, &
      fftw_execute_dft, fftw_alloc_complex, fftw_free, fftw_destroy_plan, FFTW_ESTIMATE, FFTW_MEASURE, FFTW_FORWARD, &
      FFTW_BACKWARD, FFTW_MPI_DEFAULT_BLOCK, fftwf_mpi_plan_many_transpose, fftwf_mpi_execute_r2r, &
      fftwf_plan_many_dft_r2c, fftwf_plan_many_dft_c2r, fftwf_plan_many_dft, fftwf_execute_dft_r2c, &
      fftwf_execute_dft_c2r, fftwf_execute_dft, fftwf_destroy_plan
   use femcod_kinds, only: dp, sp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED, STATUS_USAGE
   use femcod_love, only: love_influence, surface_compliance
   use femcod_spring, only: spring_stiffness
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: cg_settings
   use femcod_cg, only: coarse_start_forces
   use femcod_observer, only: solver_observer
   use femcod_strings, only: int_str, sig_str, format_real
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: distributed_grid, distributed_state, grid_setup, grid_free, solve_loads, column_split, coarse_factor
   public :: distribute_problem, scatter_problem, distributed_convolve

   !> One rank's part of the problem and of the distributed convolution.
   type :: distributed_grid
      type(MPI_Comm) :: comm
      integer :: ranks = 1, rank = 0
      !> Grid side, this rank's first column (0-based) and number of columns.
      integer :: np = 0, j0 = 0, nj = 0
      !> Every rank's first column (0-based) and number of columns, (0:ranks-1).
      integer, allocatable :: first(:), count(:)
      !> Pixel (nm), compliance c and spring compliance s (nm/nN), height range (nm).
      real(dp) :: pixel = 0, c = 0, s = 0, scale = 1
      !> The initial gaps (nm) of this rank's columns, (np, nj).
      real(dp), allocatable :: g0(:, :)
      logical :: preconditioned = .false.
      real(dp) :: taps(0:2, 0:2) = 0
      !> Columns per rank (the last ranks may have fewer): FFTW-MPI's block size.
      integer :: block_columns = 0
      !> The padded side m = 2 np, its half spectrum mh = np + 1; this rank's frequencies
      !> kx (0-based first, number) after the transpose.
      integer :: m = 0, mh = 0, freq_start = 0, freqs = 0
      !> Down the columns: in-place r2c / c2r, the real view (2 mh, nj), the complex
      !> (mh, nj); along the rows: the complex view (m, freqs), its first np*freqs values
      !> the transpose's (np, freqs).
      type(c_ptr) :: column_memory = c_null_ptr, row_memory = c_null_ptr
      real(c_double), pointer :: column_real(:, :) => null(), column_flat(:) => null(), row_flat(:) => null()
      complex(c_double_complex), pointer :: columns(:, :) => null(), rows(:, :) => null(), row_values(:) => null()
      type(c_ptr) :: columns_forward = c_null_ptr, columns_backward = c_null_ptr, rows_forward = c_null_ptr, &
         rows_backward = c_null_ptr, to_rows = c_null_ptr, to_columns = c_null_ptr
      !> The kernel's spectrum over m^2 (real: the table is even), (m, freqs).
      real(dp), allocatable :: kernel(:, :)
      !> float32 transforms (cg_settings%single_until > 0): views of the same memory, their
      !> own plans, the kernel rounded to float32.
      logical :: has_single = .false.
      real(c_float), pointer :: column32_real(:, :) => null(), column32_flat(:) => null(), row32_flat(:) => null()
      complex(c_float_complex), pointer :: columns32(:, :) => null(), rows32(:, :) => null(), &
         row32_values(:) => null()
      type(c_ptr) :: columns_forward32 = c_null_ptr, columns_backward32 = c_null_ptr, rows_forward32 = c_null_ptr, &
         rows_backward32 = c_null_ptr, to_rows32 = c_null_ptr, to_columns32 = c_null_ptr
      real(sp), allocatable :: kernel32(:, :)
      !> Wall seconds so far in the transforms (the 1-D transforms and FFTW-MPI's
      !> transposes) and in the solver's other communication (sums, halos; waiting for
      !> slower ranks included).
      real(dp) :: transform_seconds = 0, communication_seconds = 0
   end type distributed_grid

   !> What the solver reached at one load (the same quantities as femcod_cg's residuals).
   type :: distributed_state
      real(dp) :: load = 0, approach = 0, residual = 0, penetration = 0, contact_gap = 0, load_error = 0
      real(dp) :: max_pressure = 0, seconds = 0
      !> Of `seconds`: in the transforms and in communication (distributed_grid).
      real(dp) :: transform_seconds = 0, communication_seconds = 0
      integer :: contacts = 0, iterations = 0, coarse_iterations = 0, convolutions = 0
      !> Pixels whose pressure is above the hardness given to solve_loads (all ranks).
      integer :: above_hardness = 0
      !> This rank's columns: contact forces (nN) and gaps (nm, 0 at the contacts).
      real(dp), allocatable :: force(:, :), gap(:, :)
   end type distributed_state

contains

   !> The coarse start's averaging width: the smallest power of two f with f^2 >= ranks
   !> (at least 2), or 1 when NP is not a multiple of it or too small to be worth a coarse
   !> start (below 2 * how%coarsest, as in the serial solver's nested start).
   pure integer function coarse_factor(np, ranks, how) result(f)
      integer, intent(in) :: np, ranks
      type(cg_settings), intent(in) :: how
      f = 2
      do while (f*f < ranks)
         f = 2*f
      end do
      if (.not. how%nested .or. mod(np, f) /= 0 .or. np < 2*how%coarsest) f = 1
   end function coarse_factor

   !> The column split, FFTW-MPI's block distribution: every rank the same number of
   !> columns, a multiple of `block` (the coarse start's width), ceil(np / ranks) rounded
   !> up to it, the last ranks what is left (possibly none). first and count are 0-based,
   !> (0:ranks-1).
   pure subroutine column_split(np, ranks, block, first, count)
      integer, intent(in) :: np, ranks, block
      integer, allocatable, intent(out) :: first(:), count(:)
      integer :: r, width
      allocate(first(0:ranks - 1), count(0:ranks - 1))
      width = block*((np + block*ranks - 1)/(block*ranks))
      do r = 0, ranks - 1
         first(r) = min(r*width, np)
         count(r) = max(0, min(width, np - r*width))
      end do
   end subroutine column_split

   !> The distributed grid from this rank's initial gaps (g0 of the columns `first`..)
   !> and the global constants; makes the FFTW plans (the transposes FFTW-MPI's) and the
   !> kernel's spectrum.
   !> Collective over `comm`.
   subroutine grid_setup(grid, comm, np, block, g0, pixel, c, s, how, status)
      type(distributed_grid), intent(inout) :: grid
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, block
      real(dp), intent(in) :: g0(:, :)
      real(dp), intent(in) :: pixel, c, s
      type(cg_settings), intent(in) :: how
      type(status_type), intent(inout) :: status
      integer(c_intptr_t) :: alloc, dims(2), local_columns, column_start, local_freqs, freq_start
      integer(c_int) :: flags
      real(dp) :: lo, hi, kmin
      real(dp), allocatable :: line(:)
      integer :: jj, q, i, p
      call grid_free(grid)
      grid%comm = comm
      call MPI_Comm_size(comm, grid%ranks)
      call MPI_Comm_rank(comm, grid%rank)
      grid%np = np
      call column_split(np, grid%ranks, block, grid%first, grid%count)
      grid%j0 = grid%first(grid%rank)
      grid%nj = grid%count(grid%rank)
      if (minval(grid%count) < 2) then
         if (block > 1) then
            call set_error(status, STATUS_USAGE, int_str(grid%ranks)//" ranks need a grid of at least "// &
               int_str(grid%ranks*max(block, 2))//" columns (two per rank, in blocks of "//int_str(block)// &
               "); this one has "//int_str(np))
         else
            call set_error(status, STATUS_USAGE, int_str(grid%ranks)//" ranks need a grid of at least "// &
               int_str(2*grid%ranks)//" columns (two per rank); this one has "//int_str(np))
         end if
         return
      end if
      if (size(g0, 1) /= np .or. size(g0, 2) /= grid%nj) then
         call set_error(status, STATUS_USAGE, "the gaps of rank "//int_str(grid%rank)//" are not its "// &
            int_str(np)//" x "//int_str(grid%nj)//" columns")
         return
      end if
      grid%g0 = g0
      grid%pixel = pixel
      grid%c = c
      grid%s = s
      lo = minval(g0)
      hi = maxval(g0)
      call MPI_Allreduce(MPI_IN_PLACE, lo, 1, MPI_DOUBLE_PRECISION, MPI_MIN, comm)
      call MPI_Allreduce(MPI_IN_PLACE, hi, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      grid%scale = max(hi - lo, tiny(1.0_dp))
      grid%block_columns = grid%count(0)
      grid%m = 2*np
      grid%mh = np + 1
      ! The transpose of the half spectrum: [np][mh] complex by columns (blocks of
      ! block_columns) to [mh][np] by frequencies (FFTW's default block).
      dims = [integer(c_intptr_t) :: np, grid%mh]
      alloc = fftw_mpi_local_size_many_transposed(2_c_int, dims, 2_c_intptr_t, int(grid%block_columns, c_intptr_t), &
         FFTW_MPI_DEFAULT_BLOCK, comm%MPI_VAL, local_columns, column_start, local_freqs, freq_start)
      if (int(local_columns) /= grid%nj .or. int(column_start) /= grid%j0) then
         call set_error(status, STATUS_NUMERICAL, "FFTW-MPI splits the columns otherwise than the solver: rank "// &
            int_str(grid%rank)//" has "//int_str(int(local_columns))//" from "//int_str(int(column_start)))
         return
      end if
      grid%freqs = int(local_freqs)
      grid%freq_start = int(freq_start)
      grid%column_memory = fftw_alloc_complex(int(max(alloc/2, int(grid%mh, c_intptr_t)*grid%nj, 1_c_intptr_t), c_size_t))
      grid%row_memory = fftw_alloc_complex(int(max(alloc/2, int(grid%m, c_intptr_t)*grid%freqs, 1_c_intptr_t), c_size_t))
      call c_f_pointer(grid%column_memory, grid%column_real, [2*grid%mh, grid%nj])
      call c_f_pointer(grid%column_memory, grid%column_flat, [2*grid%mh*grid%nj])
      call c_f_pointer(grid%column_memory, grid%columns, [grid%mh, grid%nj])
      call c_f_pointer(grid%row_memory, grid%rows, [grid%m, max(grid%freqs, 1)])
      call c_f_pointer(grid%row_memory, grid%row_values, [grid%m*max(grid%freqs, 1)])
      call c_f_pointer(grid%row_memory, grid%row_flat, [2*grid%m*max(grid%freqs, 1)])
      flags = FFTW_ESTIMATE
      if (how%measure_plans) flags = FFTW_MEASURE
      grid%columns_forward = fftw_plan_many_dft_r2c(1_c_int, [int(grid%m, c_int)], int(grid%nj, c_int), &
         grid%column_real, [int(2*grid%mh, c_int)], 1_c_int, int(2*grid%mh, c_int), grid%columns, &
         [int(grid%mh, c_int)], 1_c_int, int(grid%mh, c_int), flags)
      grid%columns_backward = fftw_plan_many_dft_c2r(1_c_int, [int(grid%m, c_int)], int(grid%nj, c_int), &
         grid%columns, [int(grid%mh, c_int)], 1_c_int, int(grid%mh, c_int), grid%column_real, &
         [int(2*grid%mh, c_int)], 1_c_int, int(2*grid%mh, c_int), flags)
      if (grid%freqs > 0) then
         grid%rows_forward = fftw_plan_many_dft(1_c_int, [int(grid%m, c_int)], int(grid%freqs, c_int), grid%rows, &
            [int(grid%m, c_int)], 1_c_int, int(grid%m, c_int), grid%rows, [int(grid%m, c_int)], 1_c_int, &
            int(grid%m, c_int), FFTW_FORWARD, flags)
         grid%rows_backward = fftw_plan_many_dft(1_c_int, [int(grid%m, c_int)], int(grid%freqs, c_int), grid%rows, &
            [int(grid%m, c_int)], 1_c_int, int(grid%m, c_int), grid%rows, [int(grid%m, c_int)], 1_c_int, &
            int(grid%m, c_int), FFTW_BACKWARD, flags)
      end if
      grid%to_rows = fftw_mpi_plan_many_transpose(int(np, c_intptr_t), int(grid%mh, c_intptr_t), 2_c_intptr_t, &
         int(grid%block_columns, c_intptr_t), FFTW_MPI_DEFAULT_BLOCK, grid%column_flat, grid%row_flat, comm%MPI_VAL, flags)
      grid%to_columns = fftw_mpi_plan_many_transpose(int(grid%mh, c_intptr_t), int(np, c_intptr_t), 2_c_intptr_t, &
         FFTW_MPI_DEFAULT_BLOCK, int(grid%block_columns, c_intptr_t), grid%row_flat, grid%column_flat, comm%MPI_VAL, flags)
      if (.not. (c_associated(grid%columns_forward) .and. c_associated(grid%columns_backward) .and. &
         c_associated(grid%to_rows) .and. c_associated(grid%to_columns) .and. (grid%freqs == 0 .or. &
         (c_associated(grid%rows_forward) .and. c_associated(grid%rows_backward))))) then
         call set_error(status, STATUS_NUMERICAL, "FFTW made no plan for the "//int_str(grid%m)//" x "// &
            int_str(grid%m)//" grid")
         return
      end if
      ! The kernel: the Love table's even extension (offsets -(np-1)..np-1, offset +-np
      ! 0) through the same transforms; its spectrum over m^2, real.
      allocate(line(0:np - 1))
      do jj = 1, grid%nj
         q = grid%j0 + jj - 1
         line = love_influence([(p, p = 0, np - 1)], q)
         grid%column_real(1:np, jj) = line
         grid%column_real(np + 1, jj) = 0
         do i = np + 2, grid%m
            grid%column_real(i, jj) = line(grid%m - i + 1)
         end do
      end do
      call fftw_execute_dft_r2c(grid%columns_forward, grid%column_real, grid%columns)
      call fftw_mpi_execute_r2r(grid%to_rows, grid%column_flat, grid%row_flat)
      call expand_rows(grid, even=.true.)
      allocate(grid%kernel(grid%m, grid%freqs))
      if (grid%freqs > 0) then
         call fftw_execute_dft(grid%rows_forward, grid%rows, grid%rows)
         grid%kernel = real(grid%rows(:, 1:grid%freqs), dp)/real(grid%m, dp)**2
      end if
      grid%has_single = how%single_until > 0
      if (grid%has_single) then
         call c_f_pointer(grid%column_memory, grid%column32_real, [2*grid%mh, grid%nj])
         call c_f_pointer(grid%column_memory, grid%column32_flat, [2*grid%mh*grid%nj])
         call c_f_pointer(grid%column_memory, grid%columns32, [grid%mh, grid%nj])
         call c_f_pointer(grid%row_memory, grid%rows32, [grid%m, max(grid%freqs, 1)])
         call c_f_pointer(grid%row_memory, grid%row32_values, [grid%m*max(grid%freqs, 1)])
         call c_f_pointer(grid%row_memory, grid%row32_flat, [2*grid%m*max(grid%freqs, 1)])
         grid%columns_forward32 = fftwf_plan_many_dft_r2c(1_c_int, [int(grid%m, c_int)], int(grid%nj, c_int), &
            grid%column32_real, [int(2*grid%mh, c_int)], 1_c_int, int(2*grid%mh, c_int), grid%columns32, &
            [int(grid%mh, c_int)], 1_c_int, int(grid%mh, c_int), flags)
         grid%columns_backward32 = fftwf_plan_many_dft_c2r(1_c_int, [int(grid%m, c_int)], int(grid%nj, c_int), &
            grid%columns32, [int(grid%mh, c_int)], 1_c_int, int(grid%mh, c_int), grid%column32_real, &
            [int(2*grid%mh, c_int)], 1_c_int, int(2*grid%mh, c_int), flags)
         if (grid%freqs > 0) then
            grid%rows_forward32 = fftwf_plan_many_dft(1_c_int, [int(grid%m, c_int)], int(grid%freqs, c_int), &
               grid%rows32, [int(grid%m, c_int)], 1_c_int, int(grid%m, c_int), grid%rows32, [int(grid%m, c_int)], &
               1_c_int, int(grid%m, c_int), FFTW_FORWARD, flags)
            grid%rows_backward32 = fftwf_plan_many_dft(1_c_int, [int(grid%m, c_int)], int(grid%freqs, c_int), &
               grid%rows32, [int(grid%m, c_int)], 1_c_int, int(grid%m, c_int), grid%rows32, [int(grid%m, c_int)], &
               1_c_int, int(grid%m, c_int), FFTW_BACKWARD, flags)
         end if
         grid%to_rows32 = fftwf_mpi_plan_many_transpose(int(np, c_intptr_t), int(grid%mh, c_intptr_t), 2_c_intptr_t, &
            int(grid%block_columns, c_intptr_t), FFTW_MPI_DEFAULT_BLOCK, grid%column32_flat, grid%row32_flat, &
            comm%MPI_VAL, flags)
         grid%to_columns32 = fftwf_mpi_plan_many_transpose(int(grid%mh, c_intptr_t), int(np, c_intptr_t), &
            2_c_intptr_t, FFTW_MPI_DEFAULT_BLOCK, int(grid%block_columns, c_intptr_t), grid%row32_flat, &
            grid%column32_flat, comm%MPI_VAL, flags)
         if (.not. (c_associated(grid%columns_forward32) .and. c_associated(grid%columns_backward32) .and. &
            c_associated(grid%to_rows32) .and. c_associated(grid%to_columns32) .and. (grid%freqs == 0 .or. &
            (c_associated(grid%rows_forward32) .and. c_associated(grid%rows_backward32))))) then
            call set_error(status, STATUS_NUMERICAL, "FFTW made no float32 plan for the "//int_str(grid%m)//" x "// &
               int_str(grid%m)//" grid")
            return
         end if
         grid%kernel32 = real(grid%kernel, sp)
      end if
      grid%preconditioned = .false.
      grid%taps = 0
      if (how%precondition .and. np >= 3) then
         kmin = huge(1.0_dp)
         if (grid%freqs > 0) kmin = minval(grid%kernel)
         call MPI_Allreduce(MPI_IN_PLACE, kmin, 1, MPI_DOUBLE_PRECISION, MPI_MIN, comm)
         if (kmin > 0) then
            call inverse_taps(grid)
            grid%preconditioned = .true.
         end if
      end if
   end subroutine grid_setup

   !> The preconditioner's taps (femcod_convolution's inverse_kernel_taps): the centre of
   !> the inverse of the padded convolution, taps(a, b) = sum over all frequencies of
   !> cos(2 pi a kx/m) cos(2 pi b ky/m) / kernel / m^4, each rank over its own kx (weight 2
   !> for the half spectrum's inner ones), summed by MPI_Allreduce.
   subroutine inverse_taps(grid)
      type(distributed_grid), intent(inout) :: grid
      real(dp), parameter :: two_pi = 8*atan(1.0_dp)
      real(dp) :: cy(0:2), cx(0:2), w, partial(0:2, 0:2)
      integer :: l, ky, kx, a, b
      partial = 0
      do l = 1, grid%freqs
         kx = grid%freq_start + l - 1
         w = merge(1.0_dp, 2.0_dp, kx == 0 .or. kx == grid%m/2)
         cx = [(w*cos(two_pi*real(a*kx, dp)/real(grid%m, dp)), a = 0, 2)]
         do ky = 0, grid%m - 1
            cy = [(cos(two_pi*real(b*ky, dp)/real(grid%m, dp)), b = 0, 2)]
            do b = 0, 2
               partial(:, b) = partial(:, b) + cx*cy(b)/grid%kernel(ky + 1, l)
            end do
         end do
      end do
      call MPI_Allreduce(MPI_IN_PLACE, partial, 9, MPI_DOUBLE_PRECISION, MPI_SUM, grid%comm)
      grid%taps = partial/real(grid%m, dp)**4
   end subroutine inverse_taps

   !> The grid of `problem` (read on rank 0 only; the others' is not looked at) spread over
   !> the ranks of `comm` (scatter_problem), and the distributed grid made of it
   !> (grid_setup). `block` (out): the coarse start's width, coarse_factor. Collective.
   subroutine distribute_problem(problem, comm, how, grid, block, status)
      type(contact_problem), intent(in) :: problem
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      type(distributed_grid), intent(inout) :: grid
      integer, intent(out) :: block
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: local(:, :)
      real(dp) :: constants(4)
      call scatter_problem(problem, comm, how, local, constants, block)
      call grid_setup(grid, comm, nint(constants(1)), block, local, constants(2), constants(3), constants(4), how, &
         status)
   end subroutine distribute_problem

   !> Rank 0 forms the composite gaps (nm) of `problem` and sends each rank of `comm` its
   !> columns (`local`); every rank gets `constants` = [NP, pixel (nm), compliance c and
   !> the springs' compliance s (nm/nN)] and the coarse start's width `block`
   !> (coarse_factor). The column split is column_split's. Collective.
   subroutine scatter_problem(problem, comm, how, local, constants, block)
      type(contact_problem), intent(in) :: problem
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      real(dp), allocatable, intent(out) :: local(:, :)
      real(dp), intent(out) :: constants(4)
      integer, intent(out) :: block
      real(dp), allocatable :: g0(:, :)
      integer, allocatable :: first(:), count(:)
      real(dp) :: lower_top, upper_top, top
      integer :: rank, ranks, np, i, j
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      if (rank == 0) then
         np = problem%np
         ! femcod_scene's initial_gaps, element by element and without its row-wise
         ! numbering (the same values, no temporary copies of the grid).
         allocate(g0(np, np))
         lower_top = maxval(problem%lower)
         upper_top = maxval(problem%upper)
         !$omp parallel do private(i)
         do j = 1, np
            do i = 1, np
               g0(i, j) = (problem%lower(i, j) - lower_top) + (problem%upper(np + 1 - i, j) - upper_top)
            end do
         end do
         top = maxval(g0)
         !$omp parallel do private(i)
         do j = 1, np
            do i = 1, np
               g0(i, j) = top - g0(i, j)
            end do
         end do
         constants = [real(np, dp), problem%pixel, &
            surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
            surface_compliance(problem%young(2), problem%poisson(2), problem%pixel), &
            3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)]
      else
         allocate(g0(1, 1))
      end if
      call MPI_Bcast(constants, 4, MPI_DOUBLE_PRECISION, 0, comm)
      np = nint(constants(1))
      block = coarse_factor(np, ranks, how)
      call column_split(np, ranks, block, first, count)
      allocate(local(np, count(rank)))
      call MPI_Scatterv(g0, np*count, np*first, MPI_DOUBLE_PRECISION, local, np*count(rank), MPI_DOUBLE_PRECISION, 0, &
         comm)
   end subroutine scatter_problem

   !> Frees the plans, the transform memory and the column type; the grid is empty after.
   subroutine grid_free(grid)
      type(distributed_grid), intent(inout) :: grid
      integer :: k
      type(c_ptr) :: plans(6)
      plans = [grid%columns_forward, grid%columns_backward, grid%rows_forward, grid%rows_backward, grid%to_rows, &
         grid%to_columns]
      do k = 1, size(plans)
         if (c_associated(plans(k))) call fftw_destroy_plan(plans(k))
      end do
      plans = [grid%columns_forward32, grid%columns_backward32, grid%rows_forward32, grid%rows_backward32, &
         grid%to_rows32, grid%to_columns32]
      do k = 1, size(plans)
         if (c_associated(plans(k))) call fftwf_destroy_plan(plans(k))
      end do
      if (c_associated(grid%column_memory)) call fftw_free(grid%column_memory)
      if (c_associated(grid%row_memory)) call fftw_free(grid%row_memory)
      grid = distributed_grid(comm=MPI_COMM_NULL)
   end subroutine grid_free

   !> out = factor (I * f) on this rank's columns (np, nj): down the columns, transpose,
   !> along the rows, the kernel, and back. Collective.
   subroutine distributed_convolve(grid, f, out, factor, single)
      type(distributed_grid), intent(inout) :: grid
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out) :: out(:, :)
      real(dp), intent(in) :: factor
      !> In float32 (the grid made with has_single): the same steps, half the bytes.
      logical, intent(in), optional :: single
      integer :: j, k, np
      real(dp) :: t0, t1, t2, t3
      if (present(single)) then
         if (single .and. grid%has_single) then
            call convolve_single(grid, f, out, factor)
            return
         end if
      end if
      np = grid%np
      call wall_clock(t0)
      !$omp parallel do
      do j = 1, grid%nj
         grid%column_real(1:np, j) = f(:, j)
         grid%column_real(np + 1:, j) = 0
      end do
      call fftw_execute_dft_r2c(grid%columns_forward, grid%column_real, grid%columns)
      call wall_clock(t1)
      call fftw_mpi_execute_r2r(grid%to_rows, grid%column_flat, grid%row_flat)
      call wall_clock(t2)
      call expand_rows(grid, even=.false.)
      if (grid%freqs > 0) then
         call fftw_execute_dft(grid%rows_forward, grid%rows, grid%rows)
         !$omp parallel do
         do k = 1, grid%freqs
            grid%rows(:, k) = grid%rows(:, k)*(factor*grid%kernel(:, k))
         end do
         call fftw_execute_dft(grid%rows_backward, grid%rows, grid%rows)
      end if
      call compress_rows(grid)
      call wall_clock(t3)
      grid%transform_seconds = grid%transform_seconds + (t1 - t0) + (t3 - t2)
      grid%communication_seconds = grid%communication_seconds + (t2 - t1)
      call wall_clock(t0)
      call fftw_mpi_execute_r2r(grid%to_columns, grid%row_flat, grid%column_flat)
      call wall_clock(t1)
      call fftw_execute_dft_c2r(grid%columns_backward, grid%columns, grid%column_real)
      !$omp parallel do
      do j = 1, grid%nj
         out(:, j) = grid%column_real(1:np, j)
      end do
      call wall_clock(t2)
      grid%transform_seconds = grid%transform_seconds + (t2 - t1)
      grid%communication_seconds = grid%communication_seconds + (t1 - t0)
   end subroutine distributed_convolve

   !> distributed_convolve in float32.
   subroutine convolve_single(grid, f, out, factor)
      type(distributed_grid), intent(inout) :: grid
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out) :: out(:, :)
      real(dp), intent(in) :: factor
      integer :: j, k, i, np, m
      real(dp) :: t0, t1, t2, t3
      np = grid%np
      m = grid%m
      call wall_clock(t0)
      !$omp parallel do
      do j = 1, grid%nj
         grid%column32_real(1:np, j) = real(f(:, j), sp)
         grid%column32_real(np + 1:, j) = 0
      end do
      call fftwf_execute_dft_r2c(grid%columns_forward32, grid%column32_real, grid%columns32)
      call wall_clock(t1)
      call fftwf_mpi_execute_r2r(grid%to_rows32, grid%column32_flat, grid%row32_flat)
      call wall_clock(t2)
      ! As expand_rows (zero padding), in float32.
      do k = grid%freqs, 1, -1
         do i = np, 1, -1
            grid%row32_values((k - 1)*m + i) = grid%row32_values((k - 1)*np + i)
         end do
         grid%row32_values((k - 1)*m + np + 1:k*m) = 0
      end do
      if (grid%freqs > 0) then
         call fftwf_execute_dft(grid%rows_forward32, grid%rows32, grid%rows32)
         !$omp parallel do
         do k = 1, grid%freqs
            grid%rows32(:, k) = grid%rows32(:, k)*(real(factor, sp)*grid%kernel32(:, k))
         end do
         call fftwf_execute_dft(grid%rows_backward32, grid%rows32, grid%rows32)
      end if
      ! As compress_rows, in float32.
      do k = 1, grid%freqs
         do i = 1, np
            grid%row32_values((k - 1)*np + i) = grid%row32_values((k - 1)*m + i)
         end do
      end do
      call wall_clock(t3)
      grid%transform_seconds = grid%transform_seconds + (t1 - t0) + (t3 - t2)
      grid%communication_seconds = grid%communication_seconds + (t2 - t1)
      call wall_clock(t0)
      call fftwf_mpi_execute_r2r(grid%to_columns32, grid%row32_flat, grid%column32_flat)
      call wall_clock(t1)
      call fftwf_execute_dft_c2r(grid%columns_backward32, grid%columns32, grid%column32_real)
      !$omp parallel do
      do j = 1, grid%nj
         out(:, j) = real(grid%column32_real(1:np, j), dp)
      end do
      call wall_clock(t2)
      grid%transform_seconds = grid%transform_seconds + (t2 - t1)
      grid%communication_seconds = grid%communication_seconds + (t1 - t0)
   end subroutine convolve_single

   !> The transposed rows (np values per frequency, packed) spread in place to rows of m:
   !> zero-padded (even = false) or evenly extended, x(m - q) = x(q), with x(np) = 0
   !> (even = true). From the last row down, each from its end: nothing is overwritten
   !> before it is read.
   subroutine expand_rows(grid, even)
      type(distributed_grid), intent(inout) :: grid
      logical, intent(in) :: even
      integer :: k, i, np, m
      np = grid%np
      m = grid%m
      do k = grid%freqs, 1, -1
         do i = np, 1, -1
            grid%row_values((k - 1)*m + i) = grid%row_values((k - 1)*np + i)
         end do
         grid%row_values((k - 1)*m + np + 1) = 0
         if (even) then
            do i = np + 2, m
               grid%row_values((k - 1)*m + i) = grid%row_values((k - 1)*m + m - i + 2)
            end do
         else
            grid%row_values((k - 1)*m + np + 2:k*m) = 0
         end if
      end do
   end subroutine expand_rows

   !> The first np values of each row of m packed again for the transpose back (from the
   !> first row up: nothing is overwritten before it is read).
   subroutine compress_rows(grid)
      type(distributed_grid), intent(inout) :: grid
      integer :: k, i, np, m
      np = grid%np
      m = grid%m
      do k = 1, grid%freqs
         do i = 1, np
            grid%row_values((k - 1)*np + i) = grid%row_values((k - 1)*m + i)
         end do
      end do
   end subroutine compress_rows

   !> Every load of `loads` (nN, solved in ascending order, each warm-started from the
   !> last; states in the order given). `problem` is read on rank 0 only (the materials,
   !> for the coarse start). Collective.
   subroutine solve_loads(grid, problem, loads, how, block, states, status, observer, hardness)
      type(distributed_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: loads(:)
      !> GPa: the pressure above_hardness counts beyond (default: none counted).
      real(dp), intent(in), optional :: hardness
      type(cg_settings), intent(in) :: how
      !> The coarse start's averaging width (coarse_factor; 1: no coarse start).
      integer, intent(in) :: block
      type(distributed_state), allocatable, intent(out) :: states(:)
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), allocatable :: p(:, :)
      integer, allocatable :: order(:)
      real(dp) :: t0, t1, total(2), transform0, communication0
      integer :: k, kk, m
      m = size(loads)
      allocate(states(m), p(grid%np, grid%nj), order(m))
      states%load = loads
      order = [(k, k = 1, m)]
      do k = 2, m
         kk = k
         do while (kk > 1)
            if (loads(order(kk - 1)) <= loads(order(kk))) exit
            order([kk - 1, kk]) = order([kk, kk - 1])
            kk = kk - 1
         end do
      end do
      if (any(.not. loads > 0)) then
         call set_error(status, STATUS_USAGE, "every load must be positive (nN)")
         return
      end if
      p = 0
      do kk = 1, m
         k = order(kk)
         call wall_clock(t0)
         transform0 = grid%transform_seconds
         communication0 = grid%communication_seconds
         associate(st => states(k))
            if (kk == 1) then
               if (block > 1) then
                  call coarse_start(grid, problem, st%load, how, block, p, st%coarse_iterations, status, observer)
               else
                  call first_guess(grid, st%load, p)
               end if
               if (status%code /= 0) return
            end if
            call distributed_cg(grid, st%load, how%tol, how%max_iterations, how, p, st, status, observer)
            if (status%code /= 0) return
            st%force = p
            st%contacts = count(p > 0)
            total = [real(st%contacts, dp), 0.0_dp]
            if (present(hardness)) total(2) = count(p/grid%pixel**2 > hardness)
            call MPI_Allreduce(MPI_IN_PLACE, total, 2, MPI_DOUBLE_PRECISION, MPI_SUM, grid%comm)
            st%contacts = nint(total(1))
            st%above_hardness = nint(total(2))
            st%max_pressure = maxval(p)/grid%pixel**2
            call MPI_Allreduce(MPI_IN_PLACE, st%max_pressure, 1, MPI_DOUBLE_PRECISION, MPI_MAX, grid%comm)
            call wall_clock(t1)
            st%seconds = t1 - t0
            st%transform_seconds = grid%transform_seconds - transform0
            st%communication_seconds = grid%communication_seconds - communication0
            call observer%progress(kk, st%contacts, st%load, t1 - t0)
            if (st%residual > how%tol) then
               call set_error(status, STATUS_NUMERICAL, "cg: load "//format_real(st%load)//" nN: residual "// &
                  sig_str(st%residual, 2)//" after "//int_str(st%iterations)//" iterations, above --tol "// &
                  sig_str(how%tol, 2)//" (raise --max-iterations)")
               return
            end if
         end associate
      end do
   end subroutine solve_loads

   !> Start: the load spread over the pixels within a tenth of the height range of the
   !> first touch (femcod_cg's first_guess, distributed).
   subroutine first_guess(grid, total_load, p)
      type(distributed_grid), intent(in) :: grid
      real(dp), intent(in) :: total_load
      real(dp), intent(out) :: p(:, :)
      real(dp) :: lo, n
      lo = minval(grid%g0)
      call MPI_Allreduce(MPI_IN_PLACE, lo, 1, MPI_DOUBLE_PRECISION, MPI_MIN, grid%comm)
      where (grid%g0 <= lo + 0.1_dp*grid%scale)
         p = 1
      elsewhere
         p = 0
      end where
      n = sum(p)
      call MPI_Allreduce(MPI_IN_PLACE, n, 1, MPI_DOUBLE_PRECISION, MPI_SUM, grid%comm)
      p = p*(total_load/n)
   end subroutine first_guess

   !> The coarse start: the gaps averaged over f x f blocks (in femcod_cg's order for
   !> f = 2), gathered on rank 0, solved there by femcod_cg's nested start to
   !> how%coarse_tol, and each coarse force split equally over its f^2 pixels.
   subroutine coarse_start(grid, problem, total_load, how, f, p, iterations, status, observer)
      type(distributed_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: total_load
      type(cg_settings), intent(in) :: how
      integer, intent(in) :: f
      real(dp), intent(out) :: p(:, :)
      integer, intent(out) :: iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), allocatable :: local(:, :), whole(:, :), forces(:, :)
      integer, allocatable :: counts(:), displs(:)
      integer :: n, nl, i, j, di, dj, code
      character(len=512) :: message
      n = grid%np/f
      nl = grid%nj/f
      allocate(local(n, nl), counts(0:grid%ranks - 1), displs(0:grid%ranks - 1))
      !$omp parallel do private(i, di, dj)
      do j = 1, nl
         do i = 1, n
            local(i, j) = 0
            do dj = 1, f
               do di = 1, f
                  local(i, j) = local(i, j) + grid%g0(f*(i - 1) + di, f*(j - 1) + dj)
               end do
            end do
            local(i, j) = local(i, j)/f**2
         end do
      end do
      counts = n*(grid%count/f)
      displs = n*(grid%first/f)
      if (grid%rank == 0) then
         allocate(whole(n, n), forces(n, n))
      else
         allocate(whole(1, 1), forces(1, 1))
      end if
      call MPI_Gatherv(local, n*nl, MPI_DOUBLE_PRECISION, whole, counts, displs, MPI_DOUBLE_PRECISION, 0, grid%comm)
      iterations = 0
      if (grid%rank == 0) call coarse_start_forces(whole, problem, f*grid%pixel, total_load, how, forces, &
         iterations, status, observer)
      ! The coarse solve's outcome, the same on every rank.
      code = status%code
      message = ""
      if (code /= 0) message = status%message
      call MPI_Bcast(code, 1, MPI_INTEGER, 0, grid%comm)
      call MPI_Bcast(message, len(message), MPI_CHARACTER, 0, grid%comm)
      call MPI_Bcast(iterations, 1, MPI_INTEGER, 0, grid%comm)
      if (code /= 0) then
         if (status%code == 0) call set_error(status, code, trim(message))
         return
      end if
      call MPI_Scatterv(forces, counts, displs, MPI_DOUBLE_PRECISION, local, n*nl, MPI_DOUBLE_PRECISION, 0, grid%comm)
      !$omp parallel do private(i)
      do j = 1, nl
         do i = 1, n
            p(f*(i - 1) + 1:f*i, f*(j - 1) + 1:f*j) = local(i, j)/f**2
         end do
      end do
   end subroutine coarse_start

   !> femcod_cg's constrained_cg on the distributed grid, the same iteration (a change to
   !> the method there belongs here too) with every step over all pixels of the rank's
   !> slab (femcod_cg runs its contact-only steps over a list of the contacts), and a
   !> fresh convolution whenever the projection changed a force.
   subroutine distributed_cg(grid, total_load, tol, max_iterations, how, p, state, status, observer)
      type(distributed_grid), intent(inout) :: grid
      real(dp), intent(in) :: total_load, tol
      integer, intent(in) :: max_iterations
      type(cg_settings), intent(in) :: how
      real(dp), intent(inout) :: p(:, :)
      type(distributed_state), intent(inout) :: state
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), allocatable :: w(:, :), g(:, :), t(:, :), r(:, :), gm(:, :), z(:, :), g_old(:, :)
      real(dp) :: c, s, gbar, big_g, big_g_old, beta, num, den, tau, rt, rsum, tsum, rbar, psum, residual, &
         contact_gap, penetration, alpha, pn, lin, entry, zbar, cross, nc, nchanged, entered, sums(4), maxima(2), t0, t1
      integer :: np, nj, i, j, it
      logical :: restart, fresh, fresh_double, stalled, keep_old, single
      np = grid%np
      nj = grid%nj
      c = grid%c
      s = grid%s
      allocate(w(np, nj), g(np, nj), t(np, nj), r(np, nj))
      if (grid%preconditioned) then
         allocate(gm(-1:np + 2, -1:nj + 2), z(np, nj))
         gm = 0
      end if
      keep_old = how%polak_ribiere .or. how%powell_restart > 0
      if (keep_old) then
         allocate(g_old(np, nj))
         g_old = 0
      end if
      entry = 1
      if (grid%preconditioned) entry = how%entry_scale*grid%taps(0, 0)
      psum = sum(p)
      call reduce_one(psum, MPI_SUM)
      alpha = total_load/psum
      single = how%single_until > 0 .and. grid%has_single
      fresh = .true.
      restart = .true.
      big_g_old = 1
      t = 0
      it = 0
      zbar = 0
      fresh_double = .false.
      stalled = .false.
      do
         if (fresh) then
            call distributed_convolve(grid, p, w, c, single)
            state%convolutions = state%convolutions + 1
            fresh_double = .not. single
            fresh = .false.
            stalled = .false.
         end if
         nc = 0
         gbar = 0
         !$omp parallel do private(i) reduction(+:nc, gbar)
         do j = 1, nj
            do i = 1, np
               p(i, j) = alpha*p(i, j)
               w(i, j) = alpha*w(i, j)
               g(i, j) = grid%g0(i, j) + w(i, j) + s*p(i, j)
               if (p(i, j) > 0) then
                  nc = nc + 1
                  gbar = gbar + g(i, j)
               end if
            end do
         end do
         ! The stop request travels with the first sum, so that every rank stops together.
         sums(1:3) = [nc, gbar, merge(1.0_dp, 0.0_dp, observer%stop_requested())]
         call reduce(sums, 3, MPI_SUM)
         nc = sums(1)
         gbar = sums(2)
         if (sums(3) > 0) then
            call set_error(status, STATUS_INTERRUPTED, "stopped after "//int_str(it)//" iterations on the "// &
               int_str(np)//" x "//int_str(np)//" grid; the cg solver keeps no checkpoint")
            return
         end if
         alpha = 1
         if (.not. nc > 0) then
            call set_error(status, STATUS_NUMERICAL, "cg: all forces vanished")
            return
         end if
         gbar = gbar/nc
         state%approach = gbar
         big_g = 0
         cross = 0
         contact_gap = 0
         penetration = 0
         !$omp parallel do private(i) reduction(+:big_g, cross) reduction(max:contact_gap, penetration)
         do j = 1, nj
            do i = 1, np
               g(i, j) = g(i, j) - gbar
               if (p(i, j) > 0) then
                  big_g = big_g + g(i, j)**2
                  if (keep_old .and. .not. grid%preconditioned) cross = cross + g(i, j)*g_old(i, j)
                  contact_gap = max(contact_gap, abs(g(i, j)))
                  if (grid%preconditioned) gm(i, j) = g(i, j)
               else
                  penetration = max(penetration, -g(i, j))
                  if (grid%preconditioned) gm(i, j) = 0
               end if
            end do
         end do
         maxima = [contact_gap, penetration]
         call reduce(maxima, 2, MPI_MAX)
         contact_gap = maxima(1)
         penetration = maxima(2)
         residual = max(contact_gap, penetration)/grid%scale
         if (residual < tol .or. it >= max_iterations .or. stalled) then
            ! Accept only on displacements from a fresh double-precision convolution.
            if (.not. fresh_double) then
               single = .false.
               fresh = .true.
               cycle
            end if
            exit
         end if
         if (single .and. residual < how%single_until) then
            single = .false.
            fresh = .true.
            cycle
         end if
         if (grid%preconditioned) then
            call wall_clock(t0)
            call exchange_halo(grid, gm)
            call wall_clock(t1)
            grid%communication_seconds = grid%communication_seconds + (t1 - t0)
            call precondition(big_g, zbar, cross)
         else
            sums(1:2) = [big_g, cross]
            call reduce(sums, 2, MPI_SUM)
            big_g = sums(1)
            cross = sums(2)
         end if
         it = it + 1
         if (how%powell_restart > 0 .and. abs(cross) >= how%powell_restart*big_g) restart = .true.
         if (restart .or. .not. big_g_old > 0) then
            beta = 0
         else if (how%polak_ribiere) then
            beta = max(0.0_dp, (big_g - cross)/big_g_old)
         else
            beta = big_g/big_g_old
         end if
         big_g_old = big_g
         num = 0
         !$omp parallel do private(i) reduction(+:num)
         do j = 1, nj
            do i = 1, np
               if (keep_old) g_old(i, j) = g(i, j)
               if (p(i, j) > 0) then
                  if (grid%preconditioned) then
                     t(i, j) = z(i, j) - zbar + beta*t(i, j)
                  else
                     t(i, j) = g(i, j) + beta*t(i, j)
                  end if
                  num = num + g(i, j)*t(i, j)
               else
                  t(i, j) = 0
               end if
            end do
         end do
         ! The search direction's displacements in float32 whenever float32 is on (as the
         ! serial solver: their round-off scales with the step).
         call distributed_convolve(grid, t, r, c, grid%has_single .and. how%single_until > 0)
         fresh_double = .false.
         rt = 0
         rsum = 0
         tsum = 0
         !$omp parallel do private(i) reduction(+:rt, rsum, tsum)
         do j = 1, nj
            do i = 1, np
               if (p(i, j) > 0) then
                  rt = rt + (r(i, j) + s*t(i, j))*t(i, j)
                  rsum = rsum + r(i, j) + s*t(i, j)
                  tsum = tsum + t(i, j)
               end if
            end do
         end do
         sums = [num, rt, rsum, tsum]
         call reduce(sums, 4, MPI_SUM)
         num = sums(1)
         rt = sums(2)
         rsum = sums(3)
         tsum = sums(4)
         rbar = rsum/nc
         den = rt - rbar*tsum
         if (.not. abs(den) > 0) then
            stalled = .true.
            cycle
         end if
         tau = num/den
         nchanged = 0
         entered = 0
         psum = 0
         !$omp parallel do private(i, lin, pn) reduction(+:psum, nchanged, entered)
         do j = 1, nj
            do i = 1, np
               if (p(i, j) > 0) then
                  lin = p(i, j) - tau*t(i, j)
                  pn = max(lin, 0.0_dp)
               else
                  lin = 0
                  pn = 0
                  if (g(i, j) < 0) then
                     pn = -tau*entry*g(i, j)
                     entered = 1
                  end if
               end if
               p(i, j) = pn
               w(i, j) = w(i, j) - tau*r(i, j)
               psum = psum + pn
               if (pn /= lin) nchanged = nchanged + 1
            end do
         end do
         sums(1:3) = [psum, nchanged, entered]
         call reduce(sums, 3, MPI_SUM)
         psum = sums(1)
         nchanged = sums(2)
         entered = sums(3)
         restart = entered > 0 .and. how%restart_on_entry
         if (.not. psum > 0) then
            call set_error(status, STATUS_NUMERICAL, "cg: all forces vanished")
            return
         end if
         if (nchanged > 0) fresh = .true.
         alpha = total_load/psum
      end do
      psum = sum(p)
      call reduce_one(psum, MPI_SUM)
      state%iterations = state%iterations + it
      state%residual = residual
      state%contact_gap = contact_gap
      state%penetration = penetration
      state%load_error = abs(psum - total_load)/total_load
      state%gap = merge(0.0_dp, g, p > 0)
   contains
      !> values(1:n) summed (op MPI_SUM) or maximised (MPI_MAX) over the ranks, in place;
      !> the time it takes is communication.
      subroutine reduce(values, n, op)
         real(dp), intent(inout) :: values(*)
         integer, intent(in) :: n
         type(MPI_Op), intent(in) :: op
         real(dp) :: start, done
         call wall_clock(start)
         call MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE_PRECISION, op, grid%comm)
         call wall_clock(done)
         grid%communication_seconds = grid%communication_seconds + (done - start)
      end subroutine reduce

      !> One value, as `reduce`.
      subroutine reduce_one(value, op)
         real(dp), intent(inout) :: value
         type(MPI_Op), intent(in) :: op
         real(dp) :: values(1)
         values(1) = value
         call reduce(values, 1, op)
         value = values(1)
      end subroutine reduce_one

      !> femcod_cg's preconditioner on this rank's columns (the halo filled), its sums
      !> over all ranks.
      subroutine precondition(big_g, zbar, cross)
         real(dp), intent(out) :: big_g, zbar, cross
         real(dp) :: part(5)
         real(dp) :: zsum, gz, gsum, zo, osum
         integer :: ii, jj
         zsum = 0
         gz = 0
         gsum = 0
         zo = 0
         osum = 0
         associate(a => grid%taps)
            !$omp parallel do private(ii) reduction(+:zsum, gz, gsum, zo, osum)
            do jj = 1, nj
               do ii = 1, np
                  if (p(ii, jj) > 0) then
                     z(ii, jj) = a(0, 0)*gm(ii, jj) + a(1, 0)*(gm(ii - 1, jj) + gm(ii + 1, jj)) + &
                        a(0, 1)*(gm(ii, jj - 1) + gm(ii, jj + 1)) + &
                        a(1, 1)*(gm(ii - 1, jj - 1) + gm(ii + 1, jj - 1) + gm(ii - 1, jj + 1) + gm(ii + 1, jj + 1)) + &
                        a(2, 0)*(gm(ii - 2, jj) + gm(ii + 2, jj)) + a(0, 2)*(gm(ii, jj - 2) + gm(ii, jj + 2))
                     zsum = zsum + z(ii, jj)
                     gz = gz + g(ii, jj)*z(ii, jj)
                     gsum = gsum + g(ii, jj)
                     if (keep_old) then
                        zo = zo + g_old(ii, jj)*z(ii, jj)
                        osum = osum + g_old(ii, jj)
                     end if
                  end if
               end do
            end do
         end associate
         part = [zsum, gz, gsum, zo, osum]
         call reduce(part, 5, MPI_SUM)
         zbar = part(1)/nc
         big_g = part(2) - zbar*part(3)
         cross = part(4) - zbar*part(5)
      end subroutine precondition
   end subroutine distributed_cg

   !> The two columns each side of this rank's slab from its neighbours (zero beyond the
   !> grid's edges: MPI_PROC_NULL leaves them as they are).
   subroutine exchange_halo(grid, gm)
      type(distributed_grid), intent(in) :: grid
      real(dp), intent(inout) :: gm(-1:, -1:)
      integer :: left, right, n, nj
      left = merge(grid%rank - 1, MPI_PROC_NULL, grid%rank > 0)
      right = merge(grid%rank + 1, MPI_PROC_NULL, grid%rank < grid%ranks - 1)
      n = 2*size(gm, 1)
      nj = grid%nj
      ! Mine at the right edge to the right neighbour's left halo, and the reverse.
      call MPI_Sendrecv(gm(:, nj - 1:nj), n, MPI_DOUBLE_PRECISION, right, 1, gm(:, -1:0), n, MPI_DOUBLE_PRECISION, &
         left, 1, grid%comm, MPI_STATUS_IGNORE)
      call MPI_Sendrecv(gm(:, 1:2), n, MPI_DOUBLE_PRECISION, left, 2, gm(:, nj + 1:nj + 2), n, MPI_DOUBLE_PRECISION, &
         right, 2, grid%comm, MPI_STATUS_IGNORE)
   end subroutine exchange_halo
end module femcod_mpi_cg
