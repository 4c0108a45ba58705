!> femcod-mpi's result file, written by all ranks into one PREFIX.h5 with parallel HDF5:
!> rank 0 makes the groups (the serial writer's names: /deck, /loads/<kkk>, /run) before
!> the solve (begin_distributed_results); every rank writes its columns of each load's
!> pressure and gap maps as a hyperslab of one dataset, collectively (MPI-IO), as soon as
!> the load is solved (write_state_columns); rank 0 writes the attributes at the end
!> (write_distributed_results). The maps are stored transposed like the serial writer's
!> (femcod_hdf5): C order [i][j], row i of the figures first.
module femcod_mpi_results
   use mpi_f08
   use hdf5, only: hid_t, hsize_t, h5open_f, h5pcreate_f, h5pset_fapl_mpio_f, h5pset_dxpl_mpio_f, h5pclose_f, &
      h5fopen_f, h5fclose_f, h5screate_simple_f, h5sselect_hyperslab_f, h5sclose_f, h5dcreate_f, h5dwrite_f, &
      h5dclose_f, H5P_FILE_ACCESS_F, H5P_DATASET_XFER_F, H5FD_MPIO_COLLECTIVE_F, H5F_ACC_RDWR_F, H5S_SELECT_SET_F, &
      H5T_NATIVE_DOUBLE
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_IO
   use femcod_strings, only: int_str
   use femcod_hdf5, only: h5_file, h5_create, h5_reopen, h5_close, h5_group, h5_attribute, h5_write
   use femcod_results, only: load_group
   use femcod_mpi_cg, only: distributed_grid, distributed_state
   use femcod_result_schema, only: run_info, run_boundary
   use femcod_state_record, only: state_attributes
   implicit none
   private
   public :: distributed_run_info, begin_distributed_results, write_state_columns, write_distributed_results, &
      gather_block_maxima, figure_block, agree

   !> How many values of a rank's columns one collective write of a map takes by default
   !> (the transposed block write_columns holds: 8 MB).
   integer, parameter :: VALUES_PER_BLOCK = 2**20

   !> What /run records of a distributed run: the run's record (io/femcod_result_schema:
   !> version, command, times, which columns the states have), and the ranks'.
   type, extends(run_info) :: distributed_run_info
      character(len=:), allocatable :: label
      !> The ranks (the threads per rank are the parent's `threads`).
      integer :: ranks = 1
      real(dp) :: wall_seconds = 0
      !> Peak resident memory of each rank (MB).
      real(dp), allocatable :: peak_mb(:)
   end type distributed_run_info

   !> A file open on every rank for collective writes (MPI-IO).
   type :: collective_file
      type(h5_file) :: file
      integer(hid_t) :: dxpl = -1
   end type collective_file

contains

   !> Make `path` with the groups of `nstates` loads, before they are solved (rank 0;
   !> collective: `status` the same on every rank afterwards).
   subroutine begin_distributed_results(path, grid, nstates, status)
      character(len=*), intent(in) :: path
      type(distributed_grid), intent(in) :: grid
      integer, intent(in) :: nstates
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      integer :: k
      if (grid%rank == 0 .and. status%code == 0) then
         call h5_create(path, file, status)
         call h5_group(file, "/deck", status)
         call h5_group(file, "/loads", status)
         do k = 1, nstates
            call h5_group(file, load_group(k, nstates), status)
         end do
         call h5_close(file, status)
      end if
      call agree(status, grid%comm)
   end subroutine begin_distributed_results

   !> State k of n's /pressure (GPa, from `forces` in nN) and /gap (nm), and with
   !> --plastic its plastic displacement (nm): every rank its columns, collectively, into
   !> `path` (made by begin_distributed_results). `status` the same on every rank
   !> afterwards.
   subroutine write_state_columns(path, grid, k, n, state, forces, status, block_values)
      character(len=*), intent(in) :: path
      type(distributed_grid), intent(in) :: grid
      integer, intent(in) :: k, n
      type(distributed_state), intent(in) :: state
      real(dp), intent(in) :: forces(:, :)
      type(status_type), intent(inout) :: status
      !> Values of this rank's columns a collective write takes (default VALUES_PER_BLOCK;
      !> a test writes a small grid in several blocks).
      integer, intent(in), optional :: block_values
      type(collective_file) :: out
      character(len=:), allocatable :: g
      if (status%code /= 0) return
      call open_collective(path, grid, out, status)
      if (status%code /= 0) return
      g = load_group(k, n)
      call write_columns(out, grid, g//"/pressure", forces, "GPa", status, grid%pixel**2, block_values)
      call write_columns(out, grid, g//"/gap", state%gap, "nm", status, block_values=block_values)
      if (allocated(state%plastic)) call write_columns(out, grid, g//"/plastic_displacement", state%plastic, "nm", &
         status, block_values=block_values)
      call close_collective(out, status)
      call agree_on_write(grid, path, status)
   end subroutine write_state_columns

   !> Complete `path` (begun by begin_distributed_results): the scene, each state's
   !> values, the run, every rank's peak memory; the maps of any state whose columns are
   !> still in memory (write_state_columns) and with `info%tangential` the tangential
   !> maps. Collective; `status` the same on every rank afterwards.
   subroutine write_distributed_results(path, grid, states, info, status)
      character(len=*), intent(in) :: path
      type(distributed_grid), intent(in) :: grid
      type(distributed_state), intent(in) :: states(:)
      type(distributed_run_info), intent(in) :: info
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      character(len=:), allocatable :: g
      integer :: k
      if (grid%rank == 0 .and. status%code == 0) then
         call h5_reopen(path, file, status)
         call h5_attribute(file, "/deck", "label", info%label, status)
         call h5_attribute(file, "/deck", "NP", grid%np, status)
         call h5_attribute(file, "/deck", "pixel_nm", grid%pixel, status)
         do k = 1, size(states)
            g = load_group(k, size(states))
            call state_attributes(file, g, k, states(k)%state_values, grid%pixel, grid%np, info%run_info, &
               states(k)%cg, status)
         end do
         call h5_group(file, "/run", status)
         call h5_attribute(file, "/run", "femcod_version", info%version, status)
         call h5_attribute(file, "/run", "command_line", info%command_line, status)
         call h5_attribute(file, "/run", "host", info%host, status)
         call h5_attribute(file, "/run", "started", info%started, status)
         call h5_attribute(file, "/run", "finished", info%finished, status)
         call h5_attribute(file, "/run", "solver", info%solver, status)
         call h5_attribute(file, "/run", "boundary", run_boundary(info%run_info), status)
         call h5_attribute(file, "/run", "rms_slope", info%rms_slope, status)
         call h5_attribute(file, "/run", "composite_modulus_GPa", info%composite_modulus, status)
         call h5_attribute(file, "/run", "mpi_ranks", info%ranks, status)
         call h5_attribute(file, "/run", "threads_per_rank", info%threads, status)
         call h5_attribute(file, "/run", "wall_time_s", info%wall_seconds, status)
         call h5_write(file, "/run/peak_memory_MB", info%peak_mb, "MB", status)
         call h5_close(file, status)
      end if
      call agree(status, grid%comm)
      do k = 1, size(states)
         if (allocated(states(k)%force)) call write_state_columns(path, grid, k, size(states), states(k), &
            states(k)%force, status)
      end do
      if (info%tangential) call write_tangential_maps(path, grid, states, status)
   end subroutine write_distributed_results

   !> Each state's tractions shear_x, shear_y (GPa) and its stick and slip maps (1 where
   !> the contact sticks, or slips; zero where it has no contact): every rank its
   !> columns, collectively.
   subroutine write_tangential_maps(path, grid, states, status)
      character(len=*), intent(in) :: path
      type(distributed_grid), intent(in) :: grid
      type(distributed_state), intent(in) :: states(:)
      type(status_type), intent(inout) :: status
      type(collective_file) :: out
      real(dp), allocatable :: map(:, :, :)
      character(len=:), allocatable :: g
      integer :: k, n
      if (status%code /= 0) return
      call open_collective(path, grid, out, status)
      if (status%code /= 0) return
      allocate(map(grid%np, grid%nj, 4))
      do k = 1, size(states)
         g = load_group(k, size(states))
         associate(st => states(k))
            map = 0
            if (allocated(st%stick)) then
               do n = 1, size(st%stick)
                  map(st%tangential_i(n), st%tangential_j(n), :) = [st%shear_x(n)/grid%pixel**2, &
                     st%shear_y(n)/grid%pixel**2, merge(1.0_dp, 0.0_dp, st%stick(n)), merge(0.0_dp, 1.0_dp, st%stick(n))]
               end do
            end if
         end associate
         call write_columns(out, grid, g//"/shear_x", map(:, :, 1), "GPa", status)
         call write_columns(out, grid, g//"/shear_y", map(:, :, 2), "GPa", status)
         call write_columns(out, grid, g//"/stick", map(:, :, 3), "1", status)
         call write_columns(out, grid, g//"/slip", map(:, :, 4), "1", status)
      end do
      call close_collective(out, status)
      call agree_on_write(grid, path, status)
   end subroutine write_tangential_maps

   !> Open `path` on every rank of the grid for collective writes.
   subroutine open_collective(path, grid, out, status)
      character(len=*), intent(in) :: path
      type(distributed_grid), intent(in) :: grid
      type(collective_file), intent(out) :: out
      type(status_type), intent(inout) :: status
      integer(hid_t) :: fapl
      integer :: error, closing
      call h5open_f(error)
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, error)
      call h5pset_fapl_mpio_f(fapl, grid%comm%MPI_VAL, MPI_INFO_NULL%MPI_VAL, error)
      call h5fopen_f(path, H5F_ACC_RDWR_F, out%file%id, error, access_prp=fapl)
      call h5pclose_f(fapl, closing)
      if (error /= 0) then
         call set_error(status, STATUS_IO, path//": cannot open the file on every rank (MPI-IO)")
         return
      end if
      out%file%path = path
      call h5pcreate_f(H5P_DATASET_XFER_F, out%dxpl, error)
      call h5pset_dxpl_mpio_f(out%dxpl, H5FD_MPIO_COLLECTIVE_F, error)
   end subroutine open_collective

   subroutine close_collective(out, status)
      type(collective_file), intent(inout) :: out
      type(status_type), intent(inout) :: status
      integer :: error
      call h5pclose_f(out%dxpl, error)
      call h5fclose_f(out%file%id, error)
      if (error /= 0 .and. status%code == 0) call set_error(status, STATUS_IO, out%file%path//": error closing the file")
   end subroutine close_collective

   !> A failure on any rank fails the write on every rank.
   subroutine agree_on_write(grid, path, status)
      type(distributed_grid), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_type), intent(inout) :: status
      integer :: code
      code = status%code
      call MPI_Allreduce(MPI_IN_PLACE, code, 1, MPI_INTEGER, MPI_MAX, grid%comm)
      if (code /= 0 .and. status%code == 0) call set_error(status, code, path//": another rank failed to write its maps")
   end subroutine agree_on_write

   !> One NP x NP dataset `name` with `units`: this rank's columns `local` (over
   !> `divisor` when given) as its hyperslab, stored transposed (as the serial writer stores maps), a block of
   !> rows at a time so that no transposed copy of the whole slab is made. Collective.
   subroutine write_columns(out, grid, name, local, units, status, divisor, block_values)
      type(collective_file), intent(inout) :: out
      type(distributed_grid), intent(in) :: grid
      character(len=*), intent(in) :: name, units
      real(dp), intent(in) :: local(:, :)
      type(status_type), intent(inout) :: status
      !> Divides the values (forces in nN over the pixel's area: pressures).
      real(dp), intent(in), optional :: divisor
      !> Values a collective write takes (default VALUES_PER_BLOCK).
      integer, intent(in), optional :: block_values
      integer(hid_t) :: fspace, mspace, dset
      integer(hsize_t) :: dims(2), block(2), offset(2)
      real(dp), allocatable :: stored(:, :)
      integer :: e(4), error, rows, i0, ni
      if (status%code /= 0) return
      rows = VALUES_PER_BLOCK
      if (present(block_values)) rows = block_values
      rows = max(1, min(grid%np, rows/max(1, grid%nj)))
      dims = [integer(hsize_t) :: grid%np, grid%np]
      call h5screate_simple_f(2, dims, fspace, e(1))
      call h5dcreate_f(out%file%id, name, H5T_NATIVE_DOUBLE, fspace, dset, e(2))
      allocate(stored(grid%nj, rows))
      e(3:4) = 0
      do i0 = 1, grid%np, rows
         ni = min(rows, grid%np - i0 + 1)
         stored(:, 1:ni) = transpose(local(i0:i0 + ni - 1, :))
         if (present(divisor)) stored(:, 1:ni) = stored(:, 1:ni)/divisor
         block = [integer(hsize_t) :: grid%nj, ni]
         offset = [integer(hsize_t) :: grid%j0, i0 - 1]
         call h5screate_simple_f(2, block, mspace, error)
         call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset, block, error)
         call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, stored(:, 1:ni), block, error, mem_space_id=mspace, &
            file_space_id=fspace, xfer_prp=out%dxpl)
         e(3) = max(e(3), abs(error))
         call h5sclose_f(mspace, error)
      end do
      call h5dclose_f(dset, e(4))
      call h5sclose_f(fspace, error)
      if (any(e /= 0)) then
         call set_error(status, STATUS_IO, out%file%path//":"//name//": cannot write the map")
         return
      end if
      call h5_attribute(out%file, name, "units", units, status)
   end subroutine write_columns

   !> The block width of a map figure: the serial figures' (femcod_svg): at most 1024
   !> blocks per side.
   pure integer function figure_block(np)
      integer, intent(in) :: np
      figure_block = (np + 1023)/1024
   end function figure_block

   !> The largest value of each f x f block of the distributed map (np, nj per rank) on
   !> rank 0, (m, m) with m = ceil(np / f) (partial blocks at the far edges); the other
   !> ranks get a (0, 0) array. Collective. Each rank reduces its columns to the columns
   !> of blocks they touch (a block across two ranks' columns in part on each), and rank
   !> 0 takes the largest of the parts: it receives about m x m values, not m x np (at
   !> NP = 65536, 8 MB instead of 512 MB).
   subroutine gather_block_maxima(grid, local, f, blocks)
      type(distributed_grid), intent(in) :: grid
      real(dp), intent(in) :: local(:, :)
      integer, intent(in) :: f
      real(dp), allocatable, intent(out) :: blocks(:, :)
      real(dp), allocatable :: mine(:, :), parts(:, :)
      integer, allocatable :: first_block(:), touched(:)
      integer :: m, i, j, b, r, q
      m = (grid%np + f - 1)/f
      ! Rank r's columns first(r) + 1 .. first(r) + count(r) touch the block columns
      ! first_block(r) .. first_block(r) + touched(r) - 1.
      allocate(first_block(0:grid%ranks - 1), touched(0:grid%ranks - 1))
      do r = 0, grid%ranks - 1
         first_block(r) = grid%first(r)/f + 1
         touched(r) = (grid%first(r) + grid%count(r) - 1)/f + 2 - first_block(r)
      end do
      allocate(mine(m, touched(grid%rank)))
      mine = -huge(1.0_dp)
      do j = 1, grid%nj
         b = (grid%j0 + j - 1)/f + 2 - first_block(grid%rank)
         do i = 1, m
            mine(i, b) = max(mine(i, b), maxval(local((i - 1)*f + 1:min(grid%np, i*f), j)))
         end do
      end do
      if (grid%rank == 0) then
         allocate(parts(m, sum(touched)))
      else
         allocate(parts(1, 1))
      end if
      call MPI_Gatherv(mine, size(mine), MPI_DOUBLE_PRECISION, parts, m*touched, &
         m*[(sum(touched(0:r - 1)), r = 0, grid%ranks - 1)], MPI_DOUBLE_PRECISION, 0, grid%comm)
      if (grid%rank /= 0) then
         allocate(blocks(0, 0))
         return
      end if
      allocate(blocks(m, m))
      blocks = -huge(1.0_dp)
      q = 0
      do r = 0, grid%ranks - 1
         do b = 1, touched(r)
            q = q + 1
            blocks(:, first_block(r) + b - 1) = max(blocks(:, first_block(r) + b - 1), parts(:, q))
         end do
      end do
   end subroutine gather_block_maxima

   !> The worst failure of any rank (the largest code, the message of the first rank that
   !> has it), on every rank of `comm`; where only rank 0 can fail, rank 0's. Collective.
   subroutine agree(status, comm)
      type(status_type), intent(inout) :: status
      type(MPI_Comm), intent(in) :: comm
      integer :: mine(2), worst(2)
      character(len=1024) :: message
      call MPI_Comm_rank(comm, mine(2))
      mine(1) = status%code
      call MPI_Allreduce(mine, worst, 1, MPI_2INTEGER, MPI_MAXLOC, comm)
      if (worst(1) == 0) return
      message = ""
      if (mine(2) == worst(2)) message = status%message
      call MPI_Bcast(message, len(message), MPI_CHARACTER, worst(2), comm)
      if (status%code == 0) call set_error(status, worst(1), trim(message))
   end subroutine agree
end module femcod_mpi_results
