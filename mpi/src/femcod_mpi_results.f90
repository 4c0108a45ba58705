!> femcod-mpi's result file, written by all ranks into one PREFIX.h5 with parallel HDF5:
!> rank 0 writes the groups and attributes (the serial writer's names: /deck, /loads/<kkk>,
!> /run), then every rank writes its columns of each load's pressure and gap maps as a
!> hyperslab of one dataset, collectively (MPI-IO). The maps are stored transposed like
!> the serial writer's (femcod_hdf5): C order [i][j], row i of the figures first.
module femcod_mpi_results
   use mpi_f08
   use hdf5, only: hid_t, hsize_t, h5open_f, h5pcreate_f, h5pset_fapl_mpio_f, h5pset_dxpl_mpio_f, h5pclose_f, &
      h5fopen_f, h5fclose_f, h5screate_simple_f, h5sselect_hyperslab_f, h5sclose_f, h5dcreate_f, h5dwrite_f, &
      h5dclose_f, H5P_FILE_ACCESS_F, H5P_DATASET_XFER_F, H5FD_MPIO_COLLECTIVE_F, H5F_ACC_RDWR_F, H5S_SELECT_SET_F, &
      H5T_NATIVE_DOUBLE
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_IO
   use femcod_strings, only: int_str
   use femcod_hdf5, only: h5_file, h5_create, h5_close, h5_group, h5_attribute
   use femcod_results, only: load_group
   use femcod_mpi_cg, only: distributed_grid, distributed_state
   use femcod_result_schema, only: run_info, run_boundary
   use femcod_state_record, only: state_attributes
   implicit none
   private
   public :: distributed_run_info, write_distributed_results, gather_block_maxima, figure_block, agree

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

contains

   !> Write `path` (collective; `status` the same on every rank afterwards).
   subroutine write_distributed_results(path, grid, states, info, status)
      character(len=*), intent(in) :: path
      type(distributed_grid), intent(in) :: grid
      type(distributed_state), intent(in) :: states(:)
      type(distributed_run_info), intent(in) :: info
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      character(len=:), allocatable :: g
      integer :: k, code
      if (grid%rank == 0) then
         call h5_create(path, file, status)
         call h5_group(file, "/deck", status)
         call h5_attribute(file, "/deck", "label", info%label, status)
         call h5_attribute(file, "/deck", "NP", grid%np, status)
         call h5_attribute(file, "/deck", "pixel_nm", grid%pixel, status)
         call h5_group(file, "/loads", status)
         do k = 1, size(states)
            g = load_group(k, size(states))
            associate(s => states(k))
               call h5_group(file, g, status)
               call state_attributes(file, g, k, s%state_values, grid%pixel, grid%np, info%run_info, s%cg, status)
            end associate
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
         call h5_close(file, status)
      end if
      call agree(status, grid%comm)
      if (status%code /= 0) return
      if (grid%rank == 0) then
         ! The peak memory of every rank, a small dataset: written by rank 0 alone.
         call write_peaks(path, info%peak_mb, status)
      end if
      call agree(status, grid%comm)
      if (status%code /= 0) return
      call write_maps(path, grid, states, info%tangential, status)
      code = status%code
      call MPI_Allreduce(MPI_IN_PLACE, code, 1, MPI_INTEGER, MPI_MAX, grid%comm)
      if (code /= 0 .and. status%code == 0) call set_error(status, code, path//": another rank failed to write its maps")
   end subroutine write_distributed_results

   !> /run/peak_memory_MB, one value per rank.
   subroutine write_peaks(path, peak_mb, status)
      use femcod_hdf5, only: h5_write
      use hdf5, only: h5fopen_f, H5F_ACC_RDWR_F
      character(len=*), intent(in) :: path
      real(dp), intent(in) :: peak_mb(:)
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      integer :: error
      file%path = path
      call h5fopen_f(path, H5F_ACC_RDWR_F, file%id, error)
      if (error /= 0) then
         call set_error(status, STATUS_IO, path//": cannot reopen the file")
         return
      end if
      call h5_write(file, "/run/peak_memory_MB", peak_mb, "MB", status)
      call h5_close(file, status)
   end subroutine write_peaks

   !> Each load's /pressure (GPa) and /gap (nm), and with `tangential` the tractions
   !> shear_x, shear_y (GPa) and the stick and slip maps (1 where the contact sticks, or
   !> slips): every rank its columns, collectively.
   subroutine write_maps(path, grid, states, tangential, status)
      character(len=*), intent(in) :: path
      type(distributed_grid), intent(in) :: grid
      type(distributed_state), intent(in) :: states(:)
      logical, intent(in) :: tangential
      type(status_type), intent(inout) :: status
      integer(hid_t) :: fapl, dxpl, fid
      type(h5_file) :: file
      character(len=:), allocatable :: g
      integer :: error, k
      call h5open_f(error)
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, error)
      call h5pset_fapl_mpio_f(fapl, grid%comm%MPI_VAL, MPI_INFO_NULL%MPI_VAL, error)
      call h5fopen_f(path, H5F_ACC_RDWR_F, fid, error, access_prp=fapl)
      call h5pclose_f(fapl, error)
      if (error /= 0) then
         call set_error(status, STATUS_IO, path//": cannot open the file on every rank (MPI-IO)")
         return
      end if
      call h5pcreate_f(H5P_DATASET_XFER_F, dxpl, error)
      call h5pset_dxpl_mpio_f(dxpl, H5FD_MPIO_COLLECTIVE_F, error)
      file%id = fid
      file%path = path
      do k = 1, size(states)
         g = load_group(k, size(states))
         call write_map(g//"/pressure", states(k)%force/grid%pixel**2, "GPa")
         call write_map(g//"/gap", states(k)%gap, "nm")
         if (allocated(states(k)%plastic)) call write_map(g//"/plastic_displacement", states(k)%plastic, "nm")
         if (tangential) call write_tangential_maps(g, states(k))
      end do
      call h5pclose_f(dxpl, error)
      call h5fclose_f(fid, error)
      if (error /= 0 .and. status%code == 0) call set_error(status, STATUS_IO, path//": error closing the file")
   contains
      !> The tangential step's four maps of one state (zero where it has no contact).
      subroutine write_tangential_maps(g, st)
         character(len=*), intent(in) :: g
         type(distributed_state), intent(in) :: st
         real(dp), allocatable :: map(:, :, :)
         integer :: n
         allocate(map(grid%np, grid%nj, 4))
         map = 0
         if (allocated(st%stick)) then
            do n = 1, size(st%stick)
               map(st%tangential_i(n), st%tangential_j(n), :) = [st%shear_x(n)/grid%pixel**2, &
                  st%shear_y(n)/grid%pixel**2, merge(1.0_dp, 0.0_dp, st%stick(n)), merge(0.0_dp, 1.0_dp, st%stick(n))]
            end do
         end if
         call write_map(g//"/shear_x", map(:, :, 1), "GPa")
         call write_map(g//"/shear_y", map(:, :, 2), "GPa")
         call write_map(g//"/stick", map(:, :, 3), "1")
         call write_map(g//"/slip", map(:, :, 4), "1")
      end subroutine write_tangential_maps

      subroutine write_map(name, local, units)
         character(len=*), intent(in) :: name, units
         real(dp), intent(in) :: local(:, :)
         integer(hid_t) :: fspace, mspace, dset
         integer(hsize_t) :: dims(2), block(2), offset(2)
         real(dp), allocatable :: stored(:, :)
         integer :: e(6)
         if (status%code /= 0) return
         dims = [integer(hsize_t) :: grid%np, grid%np]
         block = [integer(hsize_t) :: grid%nj, grid%np]
         offset = [integer(hsize_t) :: grid%j0, 0]
         stored = transpose(local)
         call h5screate_simple_f(2, dims, fspace, e(1))
         call h5screate_simple_f(2, block, mspace, e(2))
         call h5dcreate_f(fid, name, H5T_NATIVE_DOUBLE, fspace, dset, e(3))
         call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset, block, e(4))
         call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, stored, block, e(5), mem_space_id=mspace, file_space_id=fspace, &
            xfer_prp=dxpl)
         call h5dclose_f(dset, e(6))
         call h5sclose_f(mspace, error)
         call h5sclose_f(fspace, error)
         if (any(e /= 0)) then
            call set_error(status, STATUS_IO, path//":"//name//": cannot write the map")
            return
         end if
         call h5_attribute(file, name, "units", units, status)
      end subroutine write_map
   end subroutine write_maps

   !> The block width of a map figure: the serial figures' (femcod_svg): at most 1024
   !> blocks per side.
   pure integer function figure_block(np)
      integer, intent(in) :: np
      figure_block = (np + 1023)/1024
   end function figure_block

   !> The largest value of each f x f block of the distributed map (np, nj per rank) on
   !> rank 0, (m, m) with m = ceil(np / f) (partial blocks at the far edges); the other
   !> ranks get a (0, 0) array. Collective; rank 0 holds m x np values on the way.
   subroutine gather_block_maxima(grid, local, f, blocks)
      type(distributed_grid), intent(in) :: grid
      real(dp), intent(in) :: local(:, :)
      integer, intent(in) :: f
      real(dp), allocatable, intent(out) :: blocks(:, :)
      real(dp), allocatable :: columns(:, :), all_columns(:, :)
      integer :: m, i, j
      m = (grid%np + f - 1)/f
      allocate(columns(m, grid%nj))
      do j = 1, grid%nj
         do i = 1, m
            columns(i, j) = maxval(local((i - 1)*f + 1:min(grid%np, i*f), j))
         end do
      end do
      if (grid%rank == 0) then
         allocate(all_columns(m, grid%np))
      else
         allocate(all_columns(1, 1))
      end if
      call MPI_Gatherv(columns, m*grid%nj, MPI_DOUBLE_PRECISION, all_columns, m*grid%count, m*grid%first, &
         MPI_DOUBLE_PRECISION, 0, grid%comm)
      if (grid%rank /= 0) then
         allocate(blocks(0, 0))
         return
      end if
      allocate(blocks(m, m))
      do j = 1, m
         do i = 1, m
            blocks(i, j) = maxval(all_columns(i, (j - 1)*f + 1:min(grid%np, j*f)))
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
