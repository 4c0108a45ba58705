!> The fixed-load solver (`--solver cg`, femcod_cg) on MPI ranks: the same complementarity
!> problem, method, stopping rule and residuals, with the NP x NP grid split in column slabs
!> across the ranks of a communicator.
!>
!> - The Love-kernel convolution on the zero-padded (2 NP)^2 grid is one FFTW-MPI r2c / c2r
!>   pair with FFTW_MPI_TRANSPOSED_OUT / _IN (the spectrum stays transposed: no global
!>   transpose back and forth); the kernel's spectrum is made distributed, each rank from
!>   its own rows of the padded table. FFTW-MPI gives each rank an equal share of the
!>   padded rows, so the physical columns (the first NP of 2 NP) would sit on half of the
!>   ranks: the solver keeps its fields in an even column split instead, and one
!>   MPI_Alltoallv per transform moves each column to and from the rank that transforms it
!>   (NP^2 values, a quarter of what the transform itself moves).
!> - Sums and maxima by MPI_Allreduce; the preconditioner's 13-point stencil reads two
!>   columns of each neighbour (MPI_Sendrecv).
!> - The first load starts from a coarse solution on rank 0 (femcod_cg's own nested start
!>   at NP/f, f the smallest power of two with f^2 >= ranks, so that it needs no more memory
!>   than a rank's share): with up to 4 ranks the same start as the serial solver's.
!> - All transforms in double precision, and every force the projection changes brings a
!>   fresh convolution (the serial solver adds up to `direct_corrections` of them from the
!>   Love table, which would be NP^2 values on every rank): more convolutions, the same
!>   answer (to the tolerance).
!>
!> No I/O and no stop: errors come back in a status, identical on every rank.
module femcod_mpi_cg
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_double, c_double_complex, c_intptr_t, c_int, &
      c_f_pointer, c_associated, c_size_t
   use mpi_f08
   use omp_lib, only: omp_get_max_threads
   use femcod_fftw_mpi, only: fftw_mpi_local_size_2d_transposed, fftw_mpi_plan_dft_r2c_2d, fftw_mpi_plan_dft_c2r_2d, &
      fftw_mpi_execute_dft_r2c, fftw_mpi_execute_dft_c2r, fftw_alloc_complex, fftw_free, fftw_destroy_plan, &
      FFTW_ESTIMATE, FFTW_MEASURE, FFTW_MPI_TRANSPOSED_OUT, FFTW_MPI_TRANSPOSED_IN
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED, STATUS_USAGE
   use femcod_love, only: love_influence, surface_compliance
   use femcod_spring, only: spring_stiffness
   use femcod_scene, only: initial_gaps
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: cg_settings
   use femcod_cg, only: coarse_start_forces
   use femcod_observer, only: solver_observer
   use femcod_strings, only: int_str, sig_str, format_real
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: distributed_grid, distributed_state, grid_setup, grid_free, solve_loads, column_split, coarse_factor
   public :: distribute_problem, distributed_convolve

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
      !> The padded side m = 2 np, its half spectrum mh = m/2 + 1; this rank's padded rows
      !> (columns in Fortran order) and transposed frequencies.
      integer :: m = 0, mh = 0
      integer :: row_start = 0, rows = 0, freq_start = 0, freqs = 0, physical_rows = 0
      !> Every rank's padded rows: first (0-based) and number.
      integer, allocatable :: pad_first(:), pad_count(:)
      type(c_ptr) :: memory = c_null_ptr, forward = c_null_ptr, backward = c_null_ptr
      real(c_double), pointer :: real_buffer(:, :) => null()
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
      !> The kernel's spectrum over m^2 (real: the table is even), (m, freqs).
      real(dp), allocatable :: kernel(:, :)
      !> Columns on their way to and from the transform: (np, rows).
      real(dp), allocatable :: staging(:, :)
      type(MPI_Datatype) :: column
      integer, allocatable :: send_counts(:), send_displs(:), recv_counts(:), recv_displs(:)
      !> Wall seconds so far in the transforms (FFTW-MPI's execute, its own transposes
      !> included) and in the solver's communication (the column exchange, sums, halos;
      !> waiting for slower ranks included).
      real(dp) :: transform_seconds = 0, communication_seconds = 0
   end type distributed_grid

   !> What the solver reached at one load (the same quantities as femcod_cg's residuals).
   type :: distributed_state
      real(dp) :: load = 0, approach = 0, residual = 0, penetration = 0, contact_gap = 0, load_error = 0
      real(dp) :: max_pressure = 0, seconds = 0
      !> Of `seconds`: in the transforms and in communication (distributed_grid).
      real(dp) :: transform_seconds = 0, communication_seconds = 0
      integer :: contacts = 0, iterations = 0, coarse_iterations = 0, convolutions = 0
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

   !> The column split: blocks of `block` columns dealt out as evenly as they go, the
   !> first ranks one more. first and count are 0-based, (0:ranks-1).
   pure subroutine column_split(np, ranks, block, first, count)
      integer, intent(in) :: np, ranks, block
      integer, allocatable, intent(out) :: first(:), count(:)
      integer :: r, nb
      allocate(first(0:ranks - 1), count(0:ranks - 1))
      nb = np/block
      do r = 0, ranks - 1
         count(r) = block*(nb/ranks + merge(1, 0, r < mod(nb, ranks)))
      end do
      first(0) = 0
      do r = 1, ranks - 1
         first(r) = first(r - 1) + count(r - 1)
      end do
   end subroutine column_split

   !> The distributed grid from this rank's initial gaps (g0 of the columns `first`..)
   !> and the global constants; makes the FFTW-MPI plans and the kernel's spectrum.
   !> Collective over `comm`.
   subroutine grid_setup(grid, comm, np, block, g0, pixel, c, s, how, status)
      type(distributed_grid), intent(inout) :: grid
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, block
      real(dp), intent(in) :: g0(:, :)
      real(dp), intent(in) :: pixel, c, s
      type(cg_settings), intent(in) :: how
      type(status_type), intent(inout) :: status
      integer(c_intptr_t) :: alloc, n0, n1, local_rows, row_start, local_freqs, freq_start
      integer(c_int) :: flags
      real(dp) :: lo, hi, kmin
      real(dp), allocatable :: line(:)
      integer :: r, lo_col, hi_col, jj, jpad, q, i, p
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
      ! The padded grid: C order [m][m] is Fortran (i, j); FFTW-MPI splits j (its n0).
      grid%m = 2*np
      grid%mh = np + 1
      n0 = grid%m
      n1 = grid%mh
      alloc = fftw_mpi_local_size_2d_transposed(n0, n1, comm%MPI_VAL, local_rows, row_start, local_freqs, freq_start)
      grid%rows = int(local_rows)
      grid%row_start = int(row_start)
      grid%freqs = int(local_freqs)
      grid%freq_start = int(freq_start)
      grid%physical_rows = max(0, min(grid%row_start + grid%rows, np) - grid%row_start)
      allocate(grid%pad_first(0:grid%ranks - 1), grid%pad_count(0:grid%ranks - 1))
      call MPI_Allgather(grid%row_start, 1, MPI_INTEGER, grid%pad_first, 1, MPI_INTEGER, comm)
      call MPI_Allgather(grid%rows, 1, MPI_INTEGER, grid%pad_count, 1, MPI_INTEGER, comm)
      grid%memory = fftw_alloc_complex(int(max(alloc, 1_c_intptr_t), c_size_t))
      call c_f_pointer(grid%memory, grid%real_buffer, [2*grid%mh, max(grid%rows, 1)])
      call c_f_pointer(grid%memory, grid%spectrum, [grid%m, max(grid%freqs, 1)])
      flags = FFTW_ESTIMATE
      if (how%measure_plans) flags = FFTW_MEASURE
      grid%forward = fftw_mpi_plan_dft_r2c_2d(n0, n0, grid%real_buffer, grid%spectrum, comm%MPI_VAL, &
         ior(flags, FFTW_MPI_TRANSPOSED_OUT))
      grid%backward = fftw_mpi_plan_dft_c2r_2d(n0, n0, grid%spectrum, grid%real_buffer, comm%MPI_VAL, &
         ior(flags, FFTW_MPI_TRANSPOSED_IN))
      if (.not. (c_associated(grid%forward) .and. c_associated(grid%backward))) then
         call set_error(status, STATUS_NUMERICAL, "FFTW-MPI made no plan for the "//int_str(grid%m)// &
            " x "//int_str(grid%m)//" grid")
         return
      end if
      ! Columns to and from the transforming ranks, counted in columns of np values.
      call MPI_Type_contiguous(np, MPI_DOUBLE_PRECISION, grid%column)
      call MPI_Type_commit(grid%column)
      allocate(grid%send_counts(0:grid%ranks - 1), grid%send_displs(0:grid%ranks - 1), &
         grid%recv_counts(0:grid%ranks - 1), grid%recv_displs(0:grid%ranks - 1))
      do r = 0, grid%ranks - 1
         ! Mine to rank r: my columns among r's padded rows.
         lo_col = max(grid%j0, grid%pad_first(r))
         hi_col = min(grid%j0 + grid%nj, grid%pad_first(r) + grid%pad_count(r), np)
         grid%send_counts(r) = max(0, hi_col - lo_col)
         grid%send_displs(r) = max(0, lo_col - grid%j0)
         ! Rank r's to me: its columns among my padded rows.
         lo_col = max(grid%first(r), grid%row_start)
         hi_col = min(grid%first(r) + grid%count(r), grid%row_start + grid%rows, np)
         grid%recv_counts(r) = max(0, hi_col - lo_col)
         grid%recv_displs(r) = max(0, lo_col - grid%row_start)
      end do
      allocate(grid%staging(np, max(grid%physical_rows, 1)))
      ! The kernel: the Love table at offsets -(np-1)..np-1 wrapped onto the padded grid
      ! (offset +-np stays 0), this rank's padded rows; its spectrum over m^2.
      allocate(line(0:np - 1))
      grid%real_buffer = 0
      do jj = 1, grid%rows
         jpad = grid%row_start + jj - 1
         if (jpad == np) cycle
         q = merge(jpad, grid%m - jpad, jpad < np)
         line = love_influence([(p, p = 0, np - 1)], q)
         grid%real_buffer(1:np, jj) = line
         do i = np + 2, grid%m
            grid%real_buffer(i, jj) = line(grid%m - i + 1)
         end do
      end do
      call fftw_mpi_execute_dft_r2c(grid%forward, grid%real_buffer, grid%spectrum)
      allocate(grid%kernel(grid%m, grid%freqs))
      grid%kernel = real(grid%spectrum(:, 1:grid%freqs), dp)/real(grid%m, dp)**2
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
   !> the ranks of `comm`: rank 0 forms the composite gaps (nm), the compliance and the
   !> springs' compliance (nm/nN), and sends each rank its columns. `block` (out): the
   !> coarse start's width, coarse_factor. Collective.
   subroutine distribute_problem(problem, comm, how, grid, block, status)
      type(contact_problem), intent(in) :: problem
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      type(distributed_grid), intent(inout) :: grid
      integer, intent(out) :: block
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: g0(:, :), local(:, :)
      integer, allocatable :: first(:), count(:)
      real(dp) :: scalars(4)
      integer :: rank, ranks, np
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      if (rank == 0) then
         np = problem%np
         g0 = transpose(reshape(initial_gaps(problem%lower, problem%upper), [np, np]))
         scalars = [real(np, dp), problem%pixel, &
            surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
            surface_compliance(problem%young(2), problem%poisson(2), problem%pixel), &
            3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)]
      else
         allocate(g0(1, 1))
      end if
      call MPI_Bcast(scalars, 4, MPI_DOUBLE_PRECISION, 0, comm)
      np = nint(scalars(1))
      block = coarse_factor(np, ranks, how)
      call column_split(np, ranks, block, first, count)
      allocate(local(np, count(rank)))
      call MPI_Scatterv(g0, np*count, np*first, MPI_DOUBLE_PRECISION, local, np*count(rank), MPI_DOUBLE_PRECISION, 0, &
         comm)
      deallocate(g0)
      call grid_setup(grid, comm, np, block, local, scalars(2), scalars(3), scalars(4), how, status)
   end subroutine distribute_problem

   !> Frees the plans, the transform memory and the column type; the grid is empty after.
   subroutine grid_free(grid)
      type(distributed_grid), intent(inout) :: grid
      if (c_associated(grid%forward)) call fftw_destroy_plan(grid%forward)
      if (c_associated(grid%backward)) call fftw_destroy_plan(grid%backward)
      if (c_associated(grid%memory)) call fftw_free(grid%memory)
      grid%forward = c_null_ptr
      grid%backward = c_null_ptr
      grid%memory = c_null_ptr
      nullify(grid%real_buffer, grid%spectrum)
      if (allocated(grid%send_counts)) call MPI_Type_free(grid%column)
      grid = distributed_grid(comm=MPI_COMM_NULL, column=MPI_DATATYPE_NULL)
   end subroutine grid_free

   !> out = factor (I * f) on this rank's columns: the columns to the transforming ranks,
   !> the padded transform, the kernel, the inverse, and back.
   subroutine distributed_convolve(grid, f, out, factor)
      type(distributed_grid), intent(inout) :: grid
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out) :: out(:, :)
      real(dp), intent(in) :: factor
      integer :: j, k
      real(dp) :: t0, t1, t2, t3
      call wall_clock(t0)
      call MPI_Alltoallv(f, grid%send_counts, grid%send_displs, grid%column, grid%staging, grid%recv_counts, &
         grid%recv_displs, grid%column, grid%comm)
      !$omp parallel do
      do j = 1, grid%rows
         if (j <= grid%physical_rows) then
            grid%real_buffer(1:grid%np, j) = grid%staging(:, j)
            grid%real_buffer(grid%np + 1:, j) = 0
         else
            grid%real_buffer(:, j) = 0
         end if
      end do
      call wall_clock(t1)
      call fftw_mpi_execute_dft_r2c(grid%forward, grid%real_buffer, grid%spectrum)
      !$omp parallel do
      do k = 1, grid%freqs
         grid%spectrum(:, k) = grid%spectrum(:, k)*(factor*grid%kernel(:, k))
      end do
      call fftw_mpi_execute_dft_c2r(grid%backward, grid%spectrum, grid%real_buffer)
      call wall_clock(t2)
      !$omp parallel do
      do j = 1, grid%physical_rows
         grid%staging(:, j) = grid%real_buffer(1:grid%np, j)
      end do
      call MPI_Alltoallv(grid%staging, grid%recv_counts, grid%recv_displs, grid%column, out, grid%send_counts, &
         grid%send_displs, grid%column, grid%comm)
      call wall_clock(t3)
      grid%transform_seconds = grid%transform_seconds + (t2 - t1)
      grid%communication_seconds = grid%communication_seconds + (t1 - t0) + (t3 - t2)
   end subroutine distributed_convolve

   !> Every load of `loads` (nN, solved in ascending order, each warm-started from the
   !> last; states in the order given). `problem` is read on rank 0 only (the materials,
   !> for the coarse start). Collective.
   subroutine solve_loads(grid, problem, loads, how, block, states, status, observer)
      type(distributed_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: loads(:)
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
            call MPI_Allreduce(MPI_IN_PLACE, total, 2, MPI_DOUBLE_PRECISION, MPI_SUM, grid%comm)
            st%contacts = nint(total(1))
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

   !> femcod_cg's constrained_cg on the distributed grid (double precision throughout, a
   !> fresh convolution whenever the projection changed a force).
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
      logical :: restart, fresh, fresh_double, stalled, keep_old
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
      if (grid%preconditioned) entry = grid%taps(0, 0)
      psum = sum(p)
      call reduce_one(psum, MPI_SUM)
      alpha = total_load/psum
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
            call distributed_convolve(grid, p, w, c)
            state%convolutions = state%convolutions + 1
            fresh_double = .true.
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
            if (.not. fresh_double) then
               fresh = .true.
               cycle
            end if
            exit
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
         call distributed_convolve(grid, t, r, c)
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
