!> The fixed-load solver (`--solver cg`, femcod_cg) on MPI ranks: the same complementarity
!> problem, method, stopping rule and residuals, with the NP x NP grid split in column slabs
!> across the ranks of a communicator.
!>
!> - The Love-kernel convolution on the zero-padded (2 NP)^2 grid, pruned as the serial
!>   one is (femcod_convolution): real-to-complex transforms of length 2 NP down this
!>   rank's columns (only NP of the 2 NP are not zero), the distributed transpose of the
!>   (NP + 1) x NP half spectrum (FFTW-MPI's; when every rank is on one node the row step
!>   reads its rows straight from every rank's columns in the node's shared memory),
!>   complex transforms of length 2 NP along the rows of this rank's frequencies in
!>   blocks, the kernel, and back the same way (femcod_mpi_slab_transform's
!>   slab_convolve). Only the non-zero half is transformed and moved: the full FFTW-MPI
!>   r2c of the padded grid transforms and transposes twice as much, and hands the
!>   physical columns to half of the ranks. The kernel's spectrum is made the same way
!>   from the even extension of the Love table, each rank from its own columns, and kept
!>   for half of the row frequencies (it is even). FFTW's threads within a rank.
!> - Sums and maxima by MPI_Allreduce; the preconditioner's 13-point stencil reads two
!>   columns of each neighbour (MPI_Sendrecv).
!> - The first load starts from a coarse solution at NP/f, f the smallest power of two
!>   with f^2 >= ranks (with up to 4 ranks the serial solver's first level): a coarse grid
!>   of at least 2 coarsest pixels a side is a distributed grid of its own, solved on the
!>   ranks from its own coarse start; a smaller one is solved on rank 0 by femcod_cg's
!>   nested start.
!> - float32 transforms (FFTW's fftwf, the transposes fftwf_mpi) where the serial solver
!>   uses them: the search directions always, the forces' own displacements while the
!>   residual is above `single_until`; every switch and the final answer from a fresh
!>   double convolution.
!> - Up to `direct_corrections` forces the projection changes are corrected directly from
!>   the float32 Love table, as the serial solver does, when every rank is on one node:
!>   the table (NP^2 values, 4 bytes each) is then held once in memory the node's ranks
!>   share (an MPI-3 shared window), each rank writing its own columns of it. More
!>   changes (and, on more nodes, any) go to the kernel split on the free surface, as in
!>   the serial solver: every rank gathers all the changes and corrects its own columns.
!>   Otherwise a fresh convolution: more convolutions, the same answer (to the tolerance).
!>
!> The grid is an elastic operator (model/femcod_elastic_operator) whose reductions are
!> MPI all-reduces: femcod_cg's one constrained iteration, its plastic rounds and its
!> displacement control run on it unchanged (solve_loads), and with its transform grid
!> (femcod_mpi_gap_transform) the gap-variable path of adhesion and of the cap under
!> displacement control: the options of `femcod run --solver cg` run on ranks, free
!> surface or periodic cell.
!>
!> No I/O and no stop: errors come back in a status, identical on every rank.
module femcod_mpi_cg
   use mpi_f08
   use, intrinsic :: iso_c_binding, only: c_ptr, c_f_pointer
   use, intrinsic :: iso_fortran_env, only: int64
   use femcod_mpi_slab_transform, only: slab_transform, slab_setup, slab_free, slab_forward, &
      slab_backward, slab_convolve, slab_convolve_single, slab_release_rows, EXTEND_EVEN, on_one_node
   use femcod_kinds, only: dp, sp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED, STATUS_USAGE
   use femcod_love, only: love_influence, surface_compliance
   use femcod_convolution, only: inverse_tap_sums, mirror_weights
   use femcod_mpi_patches, only: count_patches_on_ranks
   use femcod_love_periodic, only: periodic_love_spectrum_rows
   use femcod_spring, only: spring_stiffness
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: cg_settings
   use femcod_elastic_operator, only: elastic_operator, spread_load, cg_constraint, kernel_split_limit, &
      split_within_allowance, copy_and_displace_single
   use femcod_constrained_cg, only: constrained_cg, cg_residuals
   use femcod_split_correction, only: split_correction, split_free
   use femcod_cg, only: coarse_start_forces, materials_of, approach_error_bound, cg_session, cg_answer, session_start, &
      solve_target, ascending_order, refuse_beyond_full_contact, unconverged_message
   use femcod_interface_law, only: interface_law
   use femcod_shear_model, only: shear_model, friction_force
   use femcod_scene, only: slope_sums
   use femcod_contact_result, only: cg_state_diagnostics, state_values
   use femcod_mpi_gap_transform, only: distributed_gap_transform, gap_transform_setup, gap_transform_apply, &
      gap_transform_free
   use femcod_observer, only: solver_observer
   use femcod_strings, only: int_str, sig_str, format_real
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: distributed_grid, distributed_state, distributed_observer, grid_setup, grid_setup_taking, grid_free, &
      solve_loads, column_split, coarse_factor, gap_grid_setup
   public :: distribute_problem, scatter_problem, distributed_convolve, problem_constants, distributed_rms_slope

   !> One rank's part of the problem and of the distributed convolution: an elastic
   !> operator on this rank's columns (the parent type holds the grid side, the slab, the
   !> pixel, c, s, the gaps and the preconditioner's taps).
   type, extends(elastic_operator) :: distributed_grid
      type(MPI_Comm) :: comm
      integer :: ranks = 1, rank = 0
      !> Every rank's first column (0-based) and number of columns, (0:ranks-1).
      integer, allocatable :: first(:), count(:)
      !> The coarse start's averaging width (coarse_factor; 1: no coarse start), and on
      !> rank 0 the deck's materials and pixel for it (no heights).
      integer :: block = 1
      type(contact_problem) :: materials
      !> The transforms of this rank's columns (zero-padded to 2 np, or cyclic), and their
      !> wall seconds; the solver's other communication (sums, halos) is counted with the
      !> transposes'.
      type(slab_transform) :: slab
      !> The kernel's spectrum over m^2 (real: the table is even), for ky = 0 .. m/2 only
      !> (even in ky: ky and m - ky the same), (m/2 + 1, freqs).
      real(dp), allocatable :: kernel(:, :)
      !> The kernel rounded to float32 (cg_settings%single_until > 0: float32 transforms).
      real(sp), allocatable :: kernel32(:, :)
      !> The gap-variable iteration's transform grid (gap_grid_setup; femcod_mpi_gap_transform).
      type(distributed_gap_transform) :: gaps
      !> The float32 Love table I(p, q), offsets p, q = 0 .. np-1 (the serial operator's
      !> table), in the shared window `table_window` when every rank is on one node
      !> (table_window_setup); not associated: no direct corrections. A pointer because
      !> the window's memory is MPI's, not an allocatable's.
      real(sp), pointer, contiguous :: table(:, :) => null()
      type(MPI_Win) :: table_window = MPI_WIN_NULL
      !> The kernel split (femcod_split_correction) for more changes than the table takes:
      !> every rank holds its tables and the node mesh, and applies all ranks' changes to
      !> its own columns.
      type(split_correction) :: split
   contains
      procedure :: displace => distributed_displace
      procedure :: apply_spectrum => distributed_apply_spectrum
      procedure :: displace_single => distributed_displace_single
      procedure :: displace_single_in_place => distributed_displace_single_in_place
      procedure :: sum_over_grid => sum_over_ranks
      procedure :: max_over_grid => max_over_ranks
      procedure :: min_over_grid => min_over_ranks
      procedure :: any_over_grid => any_over_ranks
      procedure :: exchange_halo => exchange_halo
      procedure :: start_forces => coarse_start
      procedure :: correction_limits => ranks_correction_limits
      procedure :: add_direct => ranks_add_direct
      procedure :: split_correct => ranks_split_correct
   end type distributed_grid

   !> One requested state on the ranks: its values (model/femcod_contact_result: the
   !> totals over all ranks, the tangential tractions and stick flags of this rank's
   !> contacts), and this rank's columns of the fields.
   type, extends(state_values) :: distributed_state
      real(dp) :: seconds = 0
      !> The cg iteration's work at this state, as on one core (femcod_contact_result):
      !> iterations, residuals, the approach's error bound where there is one (fixed
      !> loads, the full kernel, no cap; -1 elsewhere), the plastic rounds.
      type(cg_state_diagnostics) :: cg
      !> With --plastic: this rank's columns of the plastic displacement (nm).
      real(dp), allocatable :: plastic(:, :)
      !> Of `seconds`: in the transforms and in communication (distributed_grid).
      real(dp) :: transform_seconds = 0, communication_seconds = 0
      !> This rank's columns: contact forces (nN; kept by the observer's choice) and gaps
      !> (nm, 0 at the contacts).
      real(dp), allocatable :: force(:, :), gap(:, :)
      !> With --tangential or --slip (femcod_mpi_shear): this rank's contact pixels (rows,
      !> columns 1 .. nj, in column order), the order of the values' tractions, and their
      !> normal forces (nN): the tangential step's input once `force` has left memory.
      integer, allocatable :: tangential_i(:), tangential_j(:)
      real(dp), allocatable :: contact_force(:)
   end type distributed_state

   !> What solve_loads tells as it goes: the serial observer's hooks, and each state's
   !> columns as soon as the state is recorded, with the solver's forces. The base keeps
   !> them (a copy of the forces in the state); femcod-mpi's observer
   !> (femcod_mpi_observer) writes them into the result file and frees them, so that a
   !> run of many states holds the columns of one, and no copy of the forces is made.
   type, extends(solver_observer) :: distributed_observer
   contains
      procedure :: columns_solved => keep_columns
   end type distributed_observer

contains

   !> State k of n (its place in the targets given, not the order of solving) is recorded
   !> on every rank, with this rank's columns of its gaps (in the state) and of its
   !> contact forces (nN, the solver's own, valid until the next state). Collective:
   !> every rank is told of the same state at the same time. The base keeps everything,
   !> the forces copied into the state.
   subroutine keep_columns(self, k, n, grid, state, forces)
      class(distributed_observer), intent(inout) :: self
      integer, intent(in) :: k, n
      type(distributed_grid), intent(inout) :: grid
      type(distributed_state), intent(inout) :: state
      real(dp), intent(in) :: forces(:, :)
      state%force = forces
   end subroutine keep_columns

   !> What every rank needs of the deck besides its columns of the gaps: [NP, pixel (nm),
   !> the composite compliance c, the springs' s (nm/nN)].
   pure function problem_constants(problem) result(constants)
      type(contact_problem), intent(in) :: problem
      real(dp) :: constants(4)
      constants = [real(problem%np, dp), problem%pixel, &
         surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), problem%pixel), &
         3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)]
   end function problem_constants

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

   !> grid_setup_taking from a copy of g0 (the caller keeps its gaps).
   subroutine grid_setup(grid, comm, np, block, g0, pixel, c, s, how, status, periodic)
      type(distributed_grid), intent(inout) :: grid
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, block
      real(dp), intent(in) :: g0(:, :)
      real(dp), intent(in) :: pixel, c, s
      type(cg_settings), intent(in) :: how
      type(status_type), intent(inout) :: status
      logical, intent(in), optional :: periodic
      real(dp), allocatable :: gaps(:, :)
      gaps = g0
      call grid_setup_taking(grid, comm, np, block, gaps, pixel, c, s, how, status, periodic)
   end subroutine grid_setup

   !> The distributed grid from this rank's initial gaps (g0 of the columns `first`..,
   !> taken into the grid: g0 is deallocated, so that the set-up does not hold them twice)
   !> and the global constants; makes the FFTW plans (femcod_mpi_slab_transform) and the
   !> kernel's spectrum.
   !> Collective over `comm`.
   subroutine grid_setup_taking(grid, comm, np, block, g0, pixel, c, s, how, status, periodic)
      type(distributed_grid), intent(inout) :: grid
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, block
      real(dp), allocatable, intent(inout) :: g0(:, :)
      real(dp), intent(in) :: pixel, c, s
      type(cg_settings), intent(in) :: how
      type(status_type), intent(inout) :: status
      !> One cell of a periodic surface (cyclic convolution on the NP x NP grid, the
      !> periodic Love kernel); default: the free surface.
      logical, intent(in), optional :: periodic
      real(dp) :: lo, hi
      call grid_free(grid)
      grid%comm = comm
      call MPI_Comm_size(comm, grid%ranks)
      call MPI_Comm_rank(comm, grid%rank)
      grid%np = np
      grid%block = block
      grid%periodic = .false.
      if (present(periodic)) grid%periodic = periodic
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
      call move_alloc(g0, grid%g0)
      grid%pixel = pixel
      grid%c = c
      grid%s = s
      lo = minval(grid%g0)
      hi = maxval(grid%g0)
      call MPI_Allreduce(MPI_IN_PLACE, lo, 1, MPI_DOUBLE_PRECISION, MPI_MIN, comm)
      call MPI_Allreduce(MPI_IN_PLACE, hi, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      grid%scale = max(hi - lo, tiny(1.0_dp))
      call slab_setup(grid%slab, comm, np, grid%j0, grid%nj, grid%count(0), grid%periodic, how%measure_plans, &
         how%single_until > 0, status)
      if (status%code /= 0) return
      call table_window_setup(grid, how)
      call kernel_spectrum(grid, how)
      if (grid%slab%has_single) grid%kernel32 = real(grid%kernel, sp)
      call preconditioner(grid, how)
      if (associated(grid%table)) then
         if (grid%periodic) call periodic_table_columns(grid)
         ! Every rank's columns written before any rank reads the table.
         call MPI_Win_fence(0, grid%table_window)
      end if
      ! The convolutions need no row memory on one node.
      call slab_release_rows(grid%slab)
   end subroutine grid_setup_taking

   !> The shared window of the Love table (distributed_grid%table), allocated by rank 0
   !> and mapped by every rank, when how%direct_corrections > 0 and every rank of the
   !> grid's communicator is on one node (one shared-memory domain). Collective.
   subroutine table_window_setup(grid, how)
      type(distributed_grid), intent(inout) :: grid
      type(cg_settings), intent(in) :: how
      type(c_ptr) :: base
      integer(MPI_ADDRESS_KIND) :: bytes
      integer :: unit
      real(sp), pointer, contiguous :: flat(:)
      if (how%direct_corrections <= 0) return
      if (.not. on_one_node(grid%comm)) return
      unit = storage_size(1.0_sp)/8
      bytes = 0
      if (grid%rank == 0) bytes = int(unit, MPI_ADDRESS_KIND)*int(grid%np, MPI_ADDRESS_KIND)**2
      call MPI_Win_allocate_shared(bytes, unit, MPI_INFO_NULL, grid%comm, base, grid%table_window)
      call MPI_Win_shared_query(grid%table_window, 0, bytes, unit, base)
      call c_f_pointer(base, flat, [int(grid%np, int64)**2])
      grid%table(0:grid%np - 1, 0:grid%np - 1) => flat
      call MPI_Win_fence(0, grid%table_window)
   end subroutine table_window_setup

   !> This rank's columns of the periodic cell's Love table: the kernel's spectrum (over
   !> m^2) transformed back. Collective.
   subroutine periodic_table_columns(grid)
      type(distributed_grid), intent(inout) :: grid
      real(dp), allocatable :: columns(:, :)
      allocate(columns(grid%np, grid%nj))
      if (grid%slab%freqs > 0) grid%slab%rows(:, 1:grid%slab%freqs) = cmplx(whole_kernel(grid), 0, dp)
      call slab_backward(grid%slab, columns)
      grid%table(:, grid%j0:grid%j0 + grid%nj - 1) = real(columns, sp)
   end subroutine periodic_table_columns

   !> Up to how%direct_corrections changes from the table where the ranks share it; the
   !> kernel split up to the serial operator's budget (elastic_operator's
   !> grid_correction_limits), for the full kernel of the free surface, on any number of
   !> nodes (it needs no table).
   subroutine ranks_correction_limits(op, how, limit, split_limit)
      class(distributed_grid), intent(in) :: op
      type(cg_settings), intent(in) :: how
      integer, intent(out) :: limit, split_limit
      limit = 0
      split_limit = 0
      if (associated(op%table)) limit = max(how%direct_corrections, 0)
      if (.not. (op%periodic .or. how%kernel_radius > 0)) split_limit = kernel_split_limit(op%np, how)
   end subroutine ranks_correction_limits

   !> w += c I * (every rank's changed forces), on this rank's columns: the changes of all
   !> ranks gathered in rank order (each rank's sorted by column, then row: the serial
   !> solver's order) and summed from the shared table. Collective.
   subroutine ranks_add_direct(op, w, changed, delta, n)
      class(distributed_grid), intent(in) :: op
      real(dp), intent(inout) :: w(:, :)
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n
      integer, allocatable :: every(:, :)
      real(dp), allocatable :: deltas(:)
      integer :: total, q, jj, ii, iq, jq
      call gather_changes(op, changed, delta, n, every, deltas, total)
      !$omp parallel do private(ii, q, iq, jq)
      do jj = 1, op%nj
         do q = 1, total
            iq = every(1, q)
            jq = every(2, q)
            do ii = 1, op%np
               w(ii, jj) = w(ii, jj) + op%c*deltas(q)*real(op%table(abs(ii - iq), abs(op%j0 + jj - jq)), dp)
            end do
         end do
      end do
   end subroutine ranks_add_direct

   !> Every rank's changes (this rank's: `changed` in its own columns, `delta`, n of them)
   !> on every rank, in rank order (each rank's sorted by column, then row: the serial
   !> solver's order), in the grid's columns (1-based): every(2, total), deltas(total).
   !> Collective.
   subroutine gather_changes(op, changed, delta, n, every, deltas, total)
      class(distributed_grid), intent(in) :: op
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n
      integer, allocatable, intent(out) :: every(:, :)
      real(dp), allocatable, intent(out) :: deltas(:)
      integer, intent(out) :: total
      integer, allocatable :: counts(:), displs(:), mine(:, :)
      integer :: r
      allocate(counts(0:op%ranks - 1), displs(0:op%ranks - 1))
      call MPI_Allgather(n, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, op%comm)
      displs(0) = 0
      do r = 1, op%ranks - 1
         displs(r) = displs(r - 1) + counts(r - 1)
      end do
      total = sum(counts)
      allocate(mine(2, max(n, 1)), every(2, max(total, 1)), deltas(max(total, 1)))
      mine(1, 1:n) = changed(1, 1:n)
      mine(2, 1:n) = changed(2, 1:n) + op%j0
      call MPI_Allgatherv(mine, 2*n, MPI_INTEGER, every, 2*counts, 2*displs, MPI_INTEGER, op%comm)
      call MPI_Allgatherv(delta, n, MPI_DOUBLE_PRECISION, deltas, counts, displs, MPI_DOUBLE_PRECISION, op%comm)
   end subroutine gather_changes

   !> The kernel split on the ranks, as elastic_operator's grid_split_correct on one
   !> process: every rank's changes gathered on every rank, the window and the error bound
   !> from all of them (the same decision on every rank), and split_apply on this rank's
   !> columns (every rank convolves the same node loads: the mesh is 1/k^2 of the grid).
   !> Collective.
   subroutine ranks_split_correct(op, w, changed, delta, n, how, allowance, split_error, applied)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(inout) :: w(:, :)
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n
      type(cg_settings), intent(in) :: how
      real(dp), intent(in) :: allowance
      real(dp), intent(inout) :: split_error
      logical, intent(out) :: applied
      integer, allocatable :: every(:, :)
      real(dp), allocatable :: deltas(:)
      integer :: total
      call gather_changes(op, changed, delta, n, every, deltas, total)
      call split_within_allowance(op%split, op%np, op%c, w, every, deltas, total, how, allowance, split_error, &
         applied, op%j0)
   end subroutine ranks_split_correct

   !> The kernel's spectrum on this rank's frequencies kx, over all ky (m values), divided
   !> by m^2 (FFTW's transforms are not normalised). Free surface: the Love table's even
   !> extension (offsets -(np-1)..np-1, offset +-np 0) through the same transforms, each
   !> rank from its own columns, truncated beyond how%kernel_radius pixels as the serial
   !> operator's table is. Periodic cell: femcod_love_periodic's spectrum, exact, for this
   !> rank's kx only (0 at zero frequency: zero-mean displacements).
   subroutine kernel_spectrum(grid, how)
      type(distributed_grid), intent(inout) :: grid
      type(cg_settings), intent(in) :: how
      real(dp), allocatable :: line(:), quarter(:, :)
      integer :: jj, q, i, p, np, l, ky
      np = grid%np
      grid%self = love_influence(0, 0)
      allocate(grid%kernel(grid%slab%m/2 + 1, grid%slab%freqs))
      if (grid%periodic) then
         ! (An expression's bounds start at 1: quarter(l, k2 + 1) is S(freq_start + l - 1, k2).)
         quarter = periodic_love_spectrum_rows(np, grid%slab%freq_start, grid%slab%freqs)
         do l = 1, grid%slab%freqs
            do ky = 0, np/2
               grid%kernel(ky + 1, l) = quarter(l, ky + 1)/real(np, dp)**2
            end do
         end do
         ! I(0, 0) of the periodic table: the mean of the spectrum over all frequencies.
         grid%self = sum_of_spectrum(grid)
         return
      end if
      allocate(line(0:np - 1))
      do jj = 1, grid%nj
         q = grid%j0 + jj - 1
         line = love_influence([(p, p = 0, np - 1)], q)
         if (how%kernel_radius > 0) where ([(real(p, dp)**2, p = 0, np - 1)] + real(q, dp)**2 > how%kernel_radius**2) &
            line = 0
         grid%slab%column_real(1:np, jj) = line
         if (associated(grid%table)) grid%table(:, q) = real(line, sp)
         grid%slab%column_real(np + 1, jj) = 0
         do i = np + 2, grid%slab%m
            grid%slab%column_real(i, jj) = line(grid%slab%m - i + 1)
         end do
      end do
      call slab_forward(grid%slab, EXTEND_EVEN)
      if (grid%slab%freqs > 0) grid%kernel = real(grid%slab%rows(1:grid%slab%m/2 + 1, 1:grid%slab%freqs), dp)/ &
         real(grid%slab%m, dp)**2
   end subroutine kernel_spectrum

   !> I(0, 0) of the periodic table from the spectrum: the sum over all m^2 frequencies of
   !> the (normalised) kernel, the half spectrum's inner kx counted twice. Collective.
   real(dp) function sum_of_spectrum(grid) result(total)
      type(distributed_grid), intent(inout) :: grid
      integer :: l, kx
      total = 0
      do l = 1, grid%slab%freqs
         kx = grid%slab%freq_start + l - 1
         total = total + merge(1.0_dp, 2.0_dp, kx == 0 .or. 2*kx == grid%slab%m)*sum(mirror_weights(grid%slab%m)* &
            grid%kernel(:, l))
      end do
      call MPI_Allreduce(MPI_IN_PLACE, total, 1, MPI_DOUBLE_PRECISION, MPI_SUM, grid%comm)
   end function sum_of_spectrum

   !> The kernel's spectrum on all m values of ky, (m, freqs), from the stored half.
   pure function whole_kernel(grid) result(whole)
      type(distributed_grid), intent(in) :: grid
      real(dp) :: whole(grid%slab%m, size(grid%kernel, 2))
      integer :: kh
      kh = grid%slab%m/2
      whole(1:kh + 1, :) = grid%kernel
      whole(kh + 2:, :) = grid%kernel(grid%slab%m - kh:2:-1, :)
   end function whole_kernel

   !> The preconditioner (how%precondition, NP >= 3) when the kernel's spectrum is
   !> positive (at every frequency but zero, for the periodic cell).
   subroutine preconditioner(grid, how)
      type(distributed_grid), intent(inout) :: grid
      type(cg_settings), intent(in) :: how
      real(dp) :: kmin
      grid%preconditioned = .false.
      grid%taps = 0
      if (.not. (how%precondition .and. grid%np >= 3)) return
      kmin = huge(1.0_dp)
      if (grid%slab%freqs > 0) kmin = minval(grid%kernel, mask=.not. zero_frequency())
      call MPI_Allreduce(MPI_IN_PLACE, kmin, 1, MPI_DOUBLE_PRECISION, MPI_MIN, grid%comm)
      if (kmin > 0) then
         call inverse_taps(grid)
         grid%preconditioned = .true.
      end if
   contains
      !> The periodic kernel's zero frequency, where it has no inverse (none for the free
      !> surface).
      function zero_frequency() result(mask)
         logical :: mask(grid%slab%m/2 + 1, grid%slab%freqs)
         mask = .false.
         if (grid%periodic .and. grid%slab%freq_start == 0) mask(1, 1) = .true.
      end function zero_frequency
   end subroutine preconditioner

   !> The preconditioner's taps (femcod_convolution's inverse_kernel_taps): the centre of
   !> the inverse of the padded convolution, femcod_convolution's inverse_tap_sums over
   !> this rank's frequencies kx (weight 2 for the half spectrum's inner ones) and all ky,
   !> summed over the ranks by MPI_Allreduce, over m^4; on the periodic cell without the
   !> zero frequency (femcod_convolution's pseudo-inverse).
   subroutine inverse_taps(grid)
      type(distributed_grid), intent(inout) :: grid
      real(dp) :: partial(0:2, 0:2)
      integer :: kx(grid%slab%freqs), k
      associate(slab => grid%slab)
         kx = [(slab%freq_start + k, k = 0, slab%freqs - 1)]
         partial = inverse_tap_sums(grid%kernel, slab%m, [(k, k = 0, slab%m/2)], mirror_weights(slab%m), kx, &
            merge(1.0_dp, 2.0_dp, kx == 0 .or. 2*kx == slab%m), 1, &
            merge([1, 1], [0, 0], grid%periodic .and. slab%freq_start == 0))
         call MPI_Allreduce(MPI_IN_PLACE, partial, 9, MPI_DOUBLE_PRECISION, MPI_SUM, grid%comm)
         grid%taps = partial/real(slab%m, dp)**4
      end associate
   end subroutine inverse_taps

   !> The grid of `problem` (read on rank 0 only; the others' is not looked at) spread over
   !> the ranks of `comm` (scatter_problem), and the distributed grid made of it
   !> (grid_setup). `block` (out): the coarse start's width, coarse_factor. Collective.
   subroutine distribute_problem(problem, comm, how, grid, block, status, periodic)
      type(contact_problem), intent(in) :: problem
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      type(distributed_grid), intent(inout) :: grid
      integer, intent(out) :: block
      type(status_type), intent(inout) :: status
      !> One periodic cell (grid_setup); default: the free surface.
      logical, intent(in), optional :: periodic
      real(dp), allocatable :: local(:, :)
      real(dp) :: constants(4)
      call scatter_problem(problem, comm, how, local, constants, block)
      call grid_setup_taking(grid, comm, nint(constants(1)), block, local, constants(2), constants(3), constants(4), &
         how, status, periodic)
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
         constants = problem_constants(problem)
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
      if (grid%table_window /= MPI_WIN_NULL) call MPI_Win_free(grid%table_window)
      grid%table => null()
      call slab_free(grid%slab)
      call gap_transform_free(grid%gaps)
      call split_free(grid%split)
      grid = distributed_grid(comm=MPI_COMM_NULL)
   end subroutine grid_free

   !> out = factor (I * f) on this rank's columns (np, nj): down the columns, transpose,
   !> along the rows, the kernel, and back (femcod_mpi_slab_transform). Collective.
   subroutine distributed_convolve(grid, f, out, factor, single)
      type(distributed_grid), intent(inout) :: grid
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out) :: out(:, :)
      real(dp), intent(in) :: factor
      !> In float32 (the grid made with float32 transforms): the same steps, half the bytes.
      logical, intent(in), optional :: single
      if (present(single)) then
         if (single .and. grid%slab%has_single) then
            call convolve_single(grid, f, factor, out)
            return
         end if
      end if
      call slab_convolve(grid%slab, f, grid%kernel, factor, out)
   end subroutine distributed_convolve

   !> distributed_convolve in float32.
   subroutine convolve_single(grid, f, factor, out, out32)
      type(distributed_grid), intent(inout) :: grid
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(in) :: factor
      real(dp), intent(out), optional :: out(:, :)
      real(sp), intent(out), optional :: out32(:, :)
      call slab_convolve_single(grid%slab, f, grid%kernel32, factor, out, out32)
   end subroutine convolve_single

   !> Every target of `targets` (loads in nN, or with `by_approach` approaches in nm;
   !> solved in ascending order, each warm-started from the last; states in the order
   !> given) by femcod_cg's solve_target on this grid: the same constrained iteration,
   !> plastic rounds (`plastic`: no pressure above `hardness`, GPa) and displacement
   !> control as `femcod run --solver cg`. Approaches with an adhesive `law`, or with the
   !> cap, are solved in the gap variables along the path in the order given, as there.
   !> `problem` is read on rank 0 only (the materials, for the coarse start). Collective.
   subroutine solve_loads(grid, problem, targets, how, states, status, observer, hardness, plastic, by_approach, law, &
      shear)
      type(distributed_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: targets(:)
      type(cg_settings), intent(in) :: how
      type(distributed_state), allocatable, intent(out) :: states(:)
      type(status_type), intent(inout) :: status
      class(distributed_observer), intent(inout) :: observer
      !> GPa: the pressure n_above_hardness counts beyond (default: none counted), and the
      !> cap with `plastic`.
      real(dp), intent(in), optional :: hardness
      logical, intent(in), optional :: plastic, by_approach
      !> The interface law (default: the hard wall; its cap is set here from `hardness`).
      type(interface_law), intent(in), optional :: law
      !> The shear model for each state's friction (default: none).
      type(shear_model), intent(in), optional :: shear
      type(shear_model) :: friction_model
      type(cg_session) :: session
      type(cg_answer) :: answer
      type(interface_law) :: interface
      integer, allocatable :: order(:)
      real(dp) :: t0, t1, transform0, communication0, cap
      integer :: k, kk, m
      logical :: capped, approaches, by_gaps
      m = size(targets)
      allocate(states(m))
      capped = .false.
      if (present(plastic)) capped = plastic
      if (present(shear)) friction_model = shear
      approaches = .false.
      if (present(by_approach)) approaches = by_approach
      cap = huge(1.0_dp)
      if (present(hardness)) cap = hardness
      if (present(law)) interface = law
      interface%area = grid%pixel**2
      interface%fmax = huge(1.0_dp)
      if (capped) interface%fmax = cap*grid%pixel**2
      by_gaps = approaches .and. (capped .or. interface%adhesive())
      call check_targets(grid, targets, approaches, capped, present(hardness), status)
      if (status%code /= 0) return
      if (approaches) then
         states%approach = targets
      else
         states%load = targets
      end if
      if (by_gaps) call gap_grid_setup(grid, status)
      if (status%code /= 0) return
      if (grid%rank == 0) grid%materials = materials_of(problem)
      call session_start(grid, session, interface, by_gaps)
      if (by_gaps) then
         order = [(k, k = 1, m)]
      else
         order = ascending_order(targets)
      end if
      do kk = 1, m
         k = order(kk)
         call wall_clock(t0)
         transform0 = grid%slab%transform_seconds
         communication0 = grid%slab%communication_seconds
         call solve_target(grid, session, targets(k), approaches, how, answer, status, observer)
         if (status%code /= 0) return
         call record_state(grid, session, answer, cap, friction_model, states(k))
         if (.not. (approaches .or. capped .or. grid%periodic .or. how%kernel_radius > 0)) states(k)%cg%approach_bound = &
            approach_error_bound(states(k)%cg%penetration, states(k)%cg%contact_gap, states(k)%cg%load_error, &
            states(k)%approach)
         call wall_clock(t1)
         associate(st => states(k))
            if (by_gaps .and. kk > 1) then
               if (states(order(kk - 1))%contacts == 0 .and. st%contacts > 0) st%jump = 1
               if (states(order(kk - 1))%contacts > 0 .and. st%contacts == 0) st%jump = -1
            end if
            st%seconds = t1 - t0
            st%transform_seconds = grid%slab%transform_seconds - transform0
            st%communication_seconds = grid%slab%communication_seconds - communication0
            call observer%progress(kk, st%contacts, st%load, t1 - t0)
            if (st%cg%residual > how%tol) then
               call set_error(status, STATUS_NUMERICAL, unconverged_message(approaches, by_gaps, targets(k), &
                  st%cg%residual, st%cg%iterations, how%tol))
               return
            end if
         end associate
         call observer%columns_solved(k, m, grid, states(k), session%p)
      end do
   end subroutine solve_loads

   !> Loads must be positive; the cap needs a hardness; approaches on a periodic cell stop
   !> short of full contact (without the cap).
   subroutine check_targets(grid, targets, approaches, capped, has_hardness, status)
      type(distributed_grid), intent(inout) :: grid
      real(dp), intent(in) :: targets(:)
      logical, intent(in) :: approaches, capped, has_hardness
      type(status_type), intent(inout) :: status
      if (.not. approaches .and. any(.not. targets > 0)) then
         call set_error(status, STATUS_USAGE, "every load must be positive (nN)")
      else if (capped .and. .not. has_hardness) then
         call set_error(status, STATUS_USAGE, "the plastic cap needs a hardness (GPa)")
      else if (approaches .and. .not. capped) then
         call refuse_beyond_full_contact(grid, targets, status)
      end if
   end subroutine check_targets

   !> One target's state from the answer and the session's forces: the residuals, this
   !> rank's maps, and the counts over all ranks (contacts, pixels above `hardness` GPa,
   !> capped pixels) with the largest pressure (GPa) and the plastic volume (nm^3). In
   !> the gap variables the contacts are the pixels at gap 0 (with adhesion they may
   !> pull), as in femcod_cg.
   subroutine record_state(grid, session, answer, hardness, shear, st)
      type(distributed_grid), intent(inout) :: grid
      type(cg_session), intent(in) :: session
      type(cg_answer), intent(inout) :: answer
      real(dp), intent(in) :: hardness
      type(shear_model), intent(in) :: shear
      type(distributed_state), intent(inout) :: st
      real(dp) :: total(6), top(1)
      logical, allocatable :: contact(:, :)
      st%reached = .true.
      st%load = answer%load
      st%approach = answer%approach
      st%cg%iterations = answer%rep%iterations
      st%cg%coarse_iterations = answer%rep%coarse_iterations
      st%cg%convolutions = answer%rep%convolutions
      st%cg%split_corrections = answer%rep%split_corrections
      st%cg%residual = answer%rep%residual
      st%cg%penetration = answer%rep%penetration
      st%cg%contact_gap = answer%rep%contact_gap
      st%cg%load_error = answer%rep%load_error
      st%cg%plastic_rounds = answer%plastic_rounds
      st%attractive = answer%attractive
      st%attractive_load = answer%attractive_load
      st%mean_gap = answer%mean_gap
      if (allocated(answer%gap)) then
         call move_alloc(answer%gap, st%gap)
      else
         ! No force (at or before first touch): the gaps at this approach.
         st%gap = grid%g0 - session%approach
      end if
      if (answer%by_gaps) then
         contact = st%gap == 0
      else
         contact = session%p > 0
      end if
      total = 0
      if (allocated(answer%plastic)) then
         call move_alloc(answer%plastic, st%plastic)
         total(3) = count(session%capped)
         total(4) = sum(st%plastic)*grid%pixel**2
      end if
      call count_patches_on_ranks(grid%comm, grid%ranks, grid%rank, grid%count, contact, grid%periodic, &
         st%patches_4, st%patches_8)
      total(1) = count(contact)
      total(2) = count(session%p/grid%pixel**2 > hardness)
      total(5) = friction_force(shear, pack(session%p, contact), grid%pixel)
      total(6) = sum(st%gap)
      call grid%sum_over_grid(total)
      ! The mean gap over the grid (nm): the gap variables' own where they ran.
      if (.not. answer%by_gaps) st%mean_gap = total(6)/real(grid%np, dp)**2
      st%friction = total(5)
      st%contacts = nint(total(1))
      st%n_above_hardness = nint(total(2))
      st%n_plastic = nint(total(3))
      st%plastic_volume = total(4)
      top(1) = -huge(1.0_dp)
      if (any(contact)) top(1) = maxval(session%p, mask=contact)/grid%pixel**2
      call grid%max_over_grid(top)
      st%max_pressure = 0
      if (st%contacts > 0) st%max_pressure = top(1)
   end subroutine record_state

   !> The coarse start (the elastic operator's start_forces): the gaps averaged over f x f
   !> blocks (f = grid%block; in femcod_cg's order for f = 2), the coarse grid solved to
   !> how%coarse_tol from its own start, and each coarse force split equally over its f^2
   !> pixels. The coarse grid is solved on the ranks (ranks_coarse_solve) when it is at
   !> least 2 how%coarsest a side, as large as the serial nested start's grids that have a
   !> start of their own; smaller ones on rank 0 (rank0_coarse_solve). With f = 1,
   !> spread_load.
   recursive subroutine coarse_start(op, target, how, p, coarse_iterations, status, observer)
      class(distributed_grid), intent(inout) :: op
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      real(dp), intent(out) :: p(:, :)
      integer, intent(inout) :: coarse_iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), allocatable :: local(:, :)
      integer :: n, nl, i, j, di, dj, f, iterations
      f = op%block
      if (f <= 1) then
         call spread_load(op, target, p)
         return
      end if
      n = op%np/f
      nl = op%nj/f
      allocate(local(n, nl))
      !$omp parallel do private(i, di, dj)
      do j = 1, nl
         do i = 1, n
            local(i, j) = 0
            do dj = 1, f
               do di = 1, f
                  local(i, j) = local(i, j) + op%g0(f*(i - 1) + di, f*(j - 1) + dj)
               end do
            end do
            local(i, j) = local(i, j)/f**2
         end do
      end do
      iterations = 0
      if (on_the_ranks(op, n, how)) then
         call ranks_coarse_solve(op, local, n, target, how, iterations, status, observer)
      else
         call rank0_coarse_solve(op, local, n, target, how, iterations, status, observer)
      end if
      if (status%code /= 0) return
      coarse_iterations = coarse_iterations + iterations
      !$omp parallel do private(i)
      do j = 1, nl
         do i = 1, n
            p(f*(i - 1) + 1:f*i, f*(j - 1) + 1:f*j) = local(i, j)/f**2
         end do
      end do
   end subroutine coarse_start

   !> Whether the n x n coarse grid of `op` is solved on the ranks: at least 2 how%coarsest
   !> a side, the full kernel (a truncated one is scaled to each grid's pixel by the
   !> serial start), and the coarse grid's own column split (coarse_factor's block) the
   !> fine one's divided by f, so that each rank keeps the columns it averaged.
   logical function on_the_ranks(op, n, how)
      class(distributed_grid), intent(in) :: op
      integer, intent(in) :: n
      type(cg_settings), intent(in) :: how
      integer, allocatable :: first(:), count(:)
      on_the_ranks = .false.
      if (n < 2*how%coarsest .or. how%kernel_radius > 0) return
      call column_split(n, op%ranks, coarse_factor(n, op%ranks, how), first, count)
      on_the_ranks = all(count == op%count/op%block) .and. all(first == op%first/op%block)
   end function on_the_ranks

   !> The coarse grid's forces solved on the ranks, as femcod_cg's nested start solves each
   !> grid on one process: the n x n grid of the averaged gaps `forces` (in: this rank's
   !> columns of them; out: its coarse forces) set up as a distributed grid at f times the
   !> pixel, its own coarse start (coarse_start, a level down), and the constrained
   !> iteration to how%coarse_tol. Collective.
   recursive subroutine ranks_coarse_solve(op, forces, n, target, how, iterations, status, observer)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(inout) :: forces(:, :)
      integer, intent(in) :: n
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      integer, intent(out) :: iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(distributed_grid) :: coarse
      type(contact_problem) :: materials
      type(cg_constraint) :: moved
      type(cg_residuals) :: rep
      real(dp) :: constants(4), lowest, approach
      iterations = 0
      ! The compliance and the springs at the coarse pixel, from rank 0's materials.
      constants = 0
      if (op%rank == 0) then
         materials = op%materials
         materials%pixel = op%block*op%pixel
         constants = problem_constants(materials)
      end if
      call MPI_Bcast(constants, 4, MPI_DOUBLE_PRECISION, 0, op%comm)
      call grid_setup(coarse, op%comm, n, coarse_factor(n, op%ranks, how), forces, op%block*op%pixel, &
         constants(3), constants(4), how, status, op%periodic)
      if (status%code /= 0) then
         call grid_free(coarse)
         return
      end if
      if (op%rank == 0) coarse%materials = op%materials
      ! femcod_cg's coarse_target: an approach moved by the coarse grid's lowest gap.
      moved = target
      if (target%by_approach) then
         lowest = minval(forces)
         call MPI_Allreduce(MPI_IN_PLACE, lowest, 1, MPI_DOUBLE_PRECISION, MPI_MIN, op%comm)
         moved%value = target%value + lowest
      end if
      call coarse_start(coarse, target, how, forces, rep%coarse_iterations, status, observer)
      if (status%code == 0) call constrained_cg(coarse, moved, how%coarse_tol, 10000, how, forces, approach, rep, &
         status, observer)
      op%slab%transform_seconds = op%slab%transform_seconds + coarse%slab%transform_seconds
      op%slab%communication_seconds = op%slab%communication_seconds + coarse%slab%communication_seconds
      call grid_free(coarse)
      iterations = rep%iterations + rep%coarse_iterations
   end subroutine ranks_coarse_solve

   !> The coarse grid's forces solved on rank 0 alone: the averaged gaps `forces` (each
   !> rank's columns) gathered there, solved by femcod_cg's nested start to
   !> how%coarse_tol, and each rank's coarse forces sent back into `forces`. The outcome
   !> and the iterations on every rank. Collective.
   subroutine rank0_coarse_solve(op, forces, n, target, how, iterations, status, observer)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(inout) :: forces(:, :)
      integer, intent(in) :: n
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      integer, intent(out) :: iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), allocatable :: whole(:, :), solved(:, :)
      integer, allocatable :: counts(:), displs(:)
      integer :: code, f
      character(len=512) :: message
      f = op%block
      counts = n*(op%count/f)
      displs = n*(op%first/f)
      if (op%rank == 0) then
         allocate(whole(n, n), solved(n, n))
      else
         allocate(whole(1, 1), solved(1, 1))
      end if
      call MPI_Gatherv(forces, size(forces), MPI_DOUBLE_PRECISION, whole, counts, displs, MPI_DOUBLE_PRECISION, 0, &
         op%comm)
      iterations = 0
      if (op%rank == 0) call coarse_start_forces(whole, op%materials, f*op%pixel, target, how, op%periodic, solved, &
         iterations, status, observer)
      ! The coarse solve's outcome, the same on every rank.
      code = status%code
      message = ""
      if (code /= 0) message = status%message
      call MPI_Bcast(code, 1, MPI_INTEGER, 0, op%comm)
      call MPI_Bcast(message, len(message), MPI_CHARACTER, 0, op%comm)
      call MPI_Bcast(iterations, 1, MPI_INTEGER, 0, op%comm)
      if (code /= 0) then
         if (status%code == 0) call set_error(status, code, trim(message))
         return
      end if
      call MPI_Scatterv(solved, counts, displs, MPI_DOUBLE_PRECISION, forces, size(forces), MPI_DOUBLE_PRECISION, 0, &
         op%comm)
   end subroutine rank0_coarse_solve

   !> The transform grid of the gap variables (femcod_mpi_gap_transform) from the grid's
   !> kernel spectrum, once. Collective.
   subroutine gap_grid_setup(grid, status)
      type(distributed_grid), intent(inout) :: grid
      type(status_type), intent(inout) :: status
      if (grid%tm > 0) return
      call gap_transform_setup(grid%gaps, grid%comm, grid%np, grid%first, grid%count, grid%slab%block_columns, &
         grid%periodic, whole_kernel(grid), grid%slab%freq_start, grid%c, grid%s, status)
      if (status%code /= 0) return
      grid%tm = grid%gaps%m
      grid%tmj = grid%gaps%columns
      grid%smallest_compliance = grid%gaps%smallest
   end subroutine gap_grid_setup

   !> out = C in or K in on this rank's transform field (the elastic operator's
   !> apply_spectrum), timed with the transforms. Collective.
   subroutine distributed_apply_spectrum(op, which, in, out)
      class(distributed_grid), intent(inout) :: op
      integer, intent(in) :: which
      real(dp), intent(in) :: in(:, :)
      real(dp), intent(out) :: out(:, :)
      real(dp) :: t0, t1
      call wall_clock(t0)
      call gap_transform_apply(op%gaps, which, in, out)
      call wall_clock(t1)
      op%slab%transform_seconds = op%slab%transform_seconds + (t1 - t0)
   end subroutine distributed_apply_spectrum

   !> out = c (I * f) on this rank's columns, in double (the elastic operator's displace).
   subroutine distributed_displace(op, f, out)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out) :: out(:, :)
      call distributed_convolve(op, f, out, op%c)
   end subroutine distributed_displace

   !> The same in float32 transforms (when the grid has them), into out or out32.
   subroutine distributed_displace_single(op, f, out, out32)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out), optional :: out(:, :)
      real(sp), intent(out), optional :: out32(:, :)
      real(dp), allocatable :: double(:, :)
      if (op%slab%has_single) then
         call convolve_single(op, f, op%c, out, out32)
      else if (present(out32)) then
         allocate(double(op%np, op%nj))
         call distributed_convolve(op, f, double, op%c)
         out32 = real(double, sp)
      else
         call distributed_convolve(op, f, out, op%c)
      end if
   end subroutine distributed_displace_single

   !> f32 replaced by c (I * f32) in float32 transforms, with no copy of f32 (when the grid
   !> has them; else as the elastic operator's base, from a copy).
   subroutine distributed_displace_single_in_place(op, f32)
      class(distributed_grid), intent(inout) :: op
      real(sp), intent(inout) :: f32(:, :)
      if (op%slab%has_single) then
         call slab_convolve_single(op%slab, kernel32=op%kernel32, factor=op%c, in_place32=f32)
      else
         call copy_and_displace_single(op, f32)
      end if
   end subroutine distributed_displace_single_in_place

   !> values(:) summed over the ranks, in place; the time it takes is communication.
   subroutine sum_over_ranks(op, values)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
      call reduce_over_ranks(op, values, MPI_SUM)
   end subroutine sum_over_ranks

   subroutine max_over_ranks(op, values)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
      call reduce_over_ranks(op, values, MPI_MAX)
   end subroutine max_over_ranks

   subroutine min_over_ranks(op, values)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
      call reduce_over_ranks(op, values, MPI_MIN)
   end subroutine min_over_ranks

   subroutine reduce_over_ranks(op, values, operation)
      class(distributed_grid), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
      type(MPI_Op), intent(in) :: operation
      real(dp) :: start, done
      call wall_clock(start)
      call MPI_Allreduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, operation, op%comm)
      call wall_clock(done)
      op%slab%communication_seconds = op%slab%communication_seconds + (done - start)
   end subroutine reduce_over_ranks

   !> True on every rank when `flag` is on one.
   logical function any_over_ranks(op, flag) result(any_flag)
      class(distributed_grid), intent(inout) :: op
      logical, intent(in) :: flag
      real(dp) :: start, done
      call wall_clock(start)
      any_flag = flag
      call MPI_Allreduce(MPI_IN_PLACE, any_flag, 1, MPI_LOGICAL, MPI_LOR, op%comm)
      call wall_clock(done)
      op%slab%communication_seconds = op%slab%communication_seconds + (done - start)
   end function any_over_ranks

   !> The two columns each side of this rank's slab from its neighbours (zero beyond the
   !> grid's edges: MPI_PROC_NULL leaves them as they are).
   subroutine exchange_halo(op, gm)
      class(distributed_grid), intent(inout) :: op
      real(sp), intent(inout) :: gm(-1:, -1:)
      integer :: left, right, n, nj
      real(dp) :: start, done
      call wall_clock(start)
      left = merge(op%rank - 1, MPI_PROC_NULL, op%rank > 0)
      right = merge(op%rank + 1, MPI_PROC_NULL, op%rank < op%ranks - 1)
      n = 2*size(gm, 1)
      nj = op%nj
      ! Mine at the right edge to the right neighbour's left halo, and the reverse.
      call MPI_Sendrecv(gm(:, nj - 1:nj), n, MPI_REAL, right, 1, gm(:, -1:0), n, MPI_REAL, left, 1, op%comm, &
         MPI_STATUS_IGNORE)
      call MPI_Sendrecv(gm(:, 1:2), n, MPI_REAL, left, 2, gm(:, nj + 1:nj + 2), n, MPI_REAL, right, 2, op%comm, &
         MPI_STATUS_IGNORE)
      call wall_clock(done)
      op%slab%communication_seconds = op%slab%communication_seconds + (done - start)
   end subroutine exchange_halo

   !> The rms slope of the initial gaps over all ranks (model/femcod_scene's rms_slope of
   !> the whole map): each slab's sums, and the pairs across its right edge with the next
   !> rank's first column (across the cell's edge too on a periodic cell). Collective.
   real(dp) function distributed_rms_slope(grid) result(slope)
      class(distributed_grid), intent(inout) :: grid
      real(dp) :: sums(2), pairs(2), total(4)
      real(dp), allocatable :: next(:)
      integer :: left, right
      call slope_sums(grid%g0, grid%periodic, sums, pairs)
      left = grid%rank - 1
      right = grid%rank + 1
      if (grid%periodic) then
         left = modulo(left, grid%ranks)
         right = modulo(right, grid%ranks)
      else
         if (left < 0) left = MPI_PROC_NULL
         if (right >= grid%ranks) right = MPI_PROC_NULL
      end if
      allocate(next(grid%np))
      call MPI_Sendrecv(grid%g0(:, 1), grid%np, MPI_DOUBLE_PRECISION, left, 3, next, grid%np, MPI_DOUBLE_PRECISION, &
         right, 3, grid%comm, MPI_STATUS_IGNORE)
      if (right /= MPI_PROC_NULL) then
         sums(2) = sums(2) + sum((next - grid%g0(:, grid%nj))**2)
         pairs(2) = pairs(2) + grid%np
      end if
      total = [sums, pairs]
      call grid%sum_over_grid(total)
      slope = sqrt(total(1)/max(total(3), 1.0_dp) + total(2)/max(total(4), 1.0_dp))/grid%pixel
   end function distributed_rms_slope
end module femcod_mpi_cg
