!> femcod-mpi's input by slabs: an HDF5 deck (femcod_deck_h5) read by every rank, each its
!> own columns of both surfaces as hyperslabs of /lower and /upper, collectively (MPI-IO);
!> a text deck streamed by rank 0 (femcod_deck_stream) in slabs of rows, each slab
!> scattered to the ranks' columns as it is read. The composite gaps are formed on the
!> ranks (femcod_scene's initial gaps, element by element, with the two maxima over all
!> ranks): no rank holds more than its columns, and rank 0 one slab besides. The height
!> files go through rank 0 (femcod_mpi_cg's scatter_problem).
!>
!> No I/O but the reading of the deck, no stop: errors come back in a status, the same on
!> every rank.
module femcod_mpi_input
   use mpi_f08
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use hdf5, only: hid_t, hsize_t, h5open_f, h5pcreate_f, h5pset_fapl_mpio_f, h5pset_dxpl_mpio_f, h5pclose_f, &
      h5fopen_f, h5fclose_f, h5screate_simple_f, h5sselect_hyperslab_f, h5sclose_f, h5dopen_f, h5dread_f, &
      h5dclose_f, h5dget_space_f, H5P_FILE_ACCESS_F, H5P_DATASET_XFER_F, H5FD_MPIO_COLLECTIVE_F, H5F_ACC_RDONLY_F, &
      H5S_SELECT_SET_F, H5T_NATIVE_DOUBLE
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_IO
   use femcod_problem, only: contact_problem, MAX_HEIGHT
   use femcod_deck_h5, only: read_deck_h5_header
   use femcod_deck_stream, only: deck_stream, open_deck_stream, read_deck_heights, close_deck_stream
   use femcod_solver_options, only: cg_settings
   use femcod_mpi_cg, only: column_split, coarse_factor, problem_constants
   use femcod_mpi_results, only: agree
   implicit none
   private
   public :: read_deck_columns, read_text_deck_columns, read_text_deck_header, slab_rows

   !> A text deck's slab: at most this many bytes of heights (and at most an eighth of a
   !> rank's columns, so that rank 0 holds within 1/8 of what every rank holds).
   integer, parameter :: SLAB_BYTES = 64*1024*1024

contains

   !> The HDF5 deck `path` on the ranks of `comm`: its header (label, NP, pixel, MAXCONT,
   !> materials; no heights) in `problem` on every rank, this rank's columns of the
   !> composite gaps in `local` (NP x its count, column_split with the coarse start's
   !> width `block`), and `constants` = [NP, pixel (nm), c, s (nm/nN)] as scatter_problem
   !> gives them. Collective.
   subroutine read_deck_columns(path, comm, how, problem, local, constants, block, status)
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      type(contact_problem), intent(out) :: problem
      real(dp), allocatable, intent(out) :: local(:, :)
      real(dp), intent(out) :: constants(4)
      integer, intent(out) :: block
      type(status_type), intent(inout) :: status
      integer, allocatable :: first(:), count(:)
      real(dp), allocatable :: lower(:, :), upper(:, :)
      integer :: rank, ranks, np, bad
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      call read_deck_h5_header(path, problem, status)
      call agree(status, comm)
      allocate(local(0, 0))
      constants = 0
      block = 1
      if (status%code /= 0) return
      np = problem%np
      constants = problem_constants(problem)
      block = coarse_factor(np, ranks, how)
      call column_split(np, ranks, block, first, count)
      call read_columns(path, comm, np, first(rank), count(rank), lower, upper, status)
      call agree(status, comm)
      if (status%code /= 0) return
      ! Every height finite and within range, on every rank.
      bad = 0
      if (.not. (all(ieee_is_finite(lower)) .and. all(ieee_is_finite(upper)))) then
         bad = 1
      else if (size(lower) > 0) then
         if (maxval(abs(lower)) > MAX_HEIGHT .or. maxval(abs(upper)) > MAX_HEIGHT) bad = 2
      end if
      call MPI_Allreduce(MPI_IN_PLACE, bad, 1, MPI_INTEGER, MPI_MAX, comm)
      if (bad == 1) call set_error(status, STATUS_BAD_INPUT, path//": heights must be finite")
      if (bad == 2) call set_error(status, STATUS_BAD_INPUT, path//": heights must lie within 1e12 nm (1 km)")
      if (status%code /= 0) return
      call composite_gaps(lower, upper, comm, local)
   end subroutine read_deck_columns

   !> The text deck `path` on the ranks of `comm`, as read_deck_columns gives an HDF5
   !> deck: rank 0 reads the header (in `problem`, on rank 0 only) and then the heights
   !> in slabs of slab_rows rows, scattering each slab's columns to their ranks as it is
   !> read; every rank forms its columns of the composite gaps. `constants` and `block`
   !> on every rank. Every message is read_deck's (file, line, what was expected).
   !> Collective.
   subroutine read_text_deck_columns(path, comm, how, problem, local, constants, block, status)
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      type(contact_problem), intent(out) :: problem
      real(dp), allocatable, intent(out) :: local(:, :)
      real(dp), intent(out) :: constants(4)
      integer, intent(out) :: block
      type(status_type), intent(inout) :: status
      type(deck_stream) :: stream
      integer, allocatable :: first(:), count(:)
      real(dp), allocatable :: lower(:, :), upper(:, :)
      integer :: rank, ranks, np
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      allocate(local(0, 0))
      constants = 0
      block = 1
      if (rank == 0) then
         call open_deck_stream(path, stream, problem, status)
         if (status%code == 0) constants = problem_constants(problem)
      end if
      call agree(status, comm)
      if (status%code /= 0) return
      call MPI_Bcast(constants, 4, MPI_DOUBLE_PRECISION, 0, comm)
      np = nint(constants(1))
      block = coarse_factor(np, ranks, how)
      call column_split(np, ranks, block, first, count)
      allocate(lower(np, count(rank)), upper(np, count(rank)))
      call scatter_surface(lower)
      if (status%code == 0) call scatter_surface(upper)
      if (rank == 0) call close_deck_stream(stream)
      if (status%code /= 0) return
      call composite_gaps(lower, upper, comm, local)
   contains
      !> One surface's NP^2 heights, row by row from the stream, slab by slab: rank 0
      !> reads a slab of rows (r x NP), every rank receives its columns of it.
      subroutine scatter_surface(map)
         real(dp), intent(out) :: map(:, :)
         real(dp), allocatable :: values(:), slab(:, :), mine(:, :)
         integer :: i0, r, rows
         rows = slab_rows(np, ranks)
         do i0 = 1, np, rows
            r = min(rows, np - i0 + 1)
            if (rank == 0) then
               allocate(values(r*np))
               call read_deck_heights(stream, values, status)
               ! slab(ii, j): row i0 + ii - 1, column j; each rank's columns contiguous.
               slab = transpose(reshape(values, [np, r]))
               deallocate(values)
            else
               allocate(slab(1, 1))
            end if
            call agree(status, comm)
            if (status%code /= 0) return
            allocate(mine(r, count(rank)))
            call MPI_Scatterv(slab, r*count, r*first, MPI_DOUBLE_PRECISION, mine, r*count(rank), &
               MPI_DOUBLE_PRECISION, 0, comm)
            map(i0:i0 + r - 1, :) = mine
            deallocate(slab, mine)
         end do
      end subroutine scatter_surface
   end subroutine read_text_deck_columns

   !> A text deck's header (label, NP, pixel, MAXCONT, materials; no heights), with
   !> read_deck's checks and messages: its first lines only are read.
   subroutine read_text_deck_header(path, problem, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(out) :: problem
      type(status_type), intent(inout) :: status
      type(deck_stream) :: stream
      call open_deck_stream(path, stream, problem, status)
      call close_deck_stream(stream)
   end subroutine read_text_deck_header

   !> The rows of a text deck's slab on `ranks` ranks: at most SLAB_BYTES of heights and
   !> at most an eighth of one rank's columns (NP / (8 ranks) rows), at least one row.
   pure integer function slab_rows(np, ranks) result(rows)
      integer, intent(in) :: np, ranks
      rows = max(1, min(np, np/(8*ranks), int(SLAB_BYTES/(8_8*np))))
   end function slab_rows

   !> This rank's columns of the composite gaps from its columns of the two surfaces
   !> (femcod_scene's initial gaps, as scatter_problem forms them on rank 0): the upper
   !> surface flipped about the horizontal axis, row i facing lower row NP + 1 - i, each
   !> surface from its highest point over all ranks, the gaps from the highest sum.
   !> Collective.
   subroutine composite_gaps(lower, upper, comm, local)
      real(dp), intent(in) :: lower(:, :), upper(:, :)
      type(MPI_Comm), intent(in) :: comm
      real(dp), allocatable, intent(out) :: local(:, :)
      real(dp) :: tops(2), top
      integer :: i, j, np
      np = size(lower, 1)
      tops = -huge(1.0_dp)
      if (size(lower) > 0) tops = [maxval(lower), maxval(upper)]
      call MPI_Allreduce(MPI_IN_PLACE, tops, 2, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      allocate(local(np, size(lower, 2)))
      !$omp parallel do private(i)
      do j = 1, size(lower, 2)
         do i = 1, np
            local(i, j) = (lower(i, j) - tops(1)) + (upper(np + 1 - i, j) - tops(2))
         end do
      end do
      top = -huge(1.0_dp)
      if (size(local) > 0) top = maxval(local)
      call MPI_Allreduce(MPI_IN_PLACE, top, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      local = top - local
   end subroutine composite_gaps

   !> Columns j0 + 1 .. j0 + nj (all NP rows) of /lower and /upper, each rank its own
   !> hyperslab, collectively. The datasets are C order [row][column]: in HDF5's Fortran
   !> view (column, row), so a rank's columns are one contiguous block of the first index.
   subroutine read_columns(path, comm, np, j0, nj, lower, upper, status)
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, j0, nj
      real(dp), allocatable, intent(out) :: lower(:, :), upper(:, :)
      type(status_type), intent(inout) :: status
      integer(hid_t) :: fapl, dxpl, fid
      integer :: error
      allocate(lower(np, nj), upper(np, nj))
      call h5open_f(error)
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, error)
      call h5pset_fapl_mpio_f(fapl, comm%MPI_VAL, MPI_INFO_NULL%MPI_VAL, error)
      call h5fopen_f(path, H5F_ACC_RDONLY_F, fid, error, access_prp=fapl)
      call h5pclose_f(fapl, error)
      if (error /= 0) then
         call set_error(status, STATUS_IO, path//": cannot open the deck on every rank (MPI-IO)")
         return
      end if
      call h5pcreate_f(H5P_DATASET_XFER_F, dxpl, error)
      call h5pset_dxpl_mpio_f(dxpl, H5FD_MPIO_COLLECTIVE_F, error)
      call read_map("/lower", lower)
      call read_map("/upper", upper)
      call h5pclose_f(dxpl, error)
      call h5fclose_f(fid, error)
   contains
      !> This rank's columns of one map, as map(row, column).
      subroutine read_map(name, map)
         character(len=*), intent(in) :: name
         real(dp), intent(out) :: map(:, :)
         integer(hid_t) :: dset, fspace, mspace
         integer(hsize_t) :: block(2), offset(2)
         real(dp), allocatable :: stored(:, :)
         integer :: e(5)
         if (status%code /= 0) return
         block = [integer(hsize_t) :: nj, np]
         offset = [integer(hsize_t) :: j0, 0]
         allocate(stored(nj, np))
         e = 0
         call h5dopen_f(fid, name, dset, e(1))
         if (e(1) == 0) call h5dget_space_f(dset, fspace, e(2))
         if (all(e == 0)) call h5sselect_hyperslab_f(fspace, H5S_SELECT_SET_F, offset, block, e(3))
         if (all(e == 0)) call h5screate_simple_f(2, block, mspace, e(4))
         if (all(e == 0)) call h5dread_f(dset, H5T_NATIVE_DOUBLE, stored, block, e(5), mem_space_id=mspace, &
            file_space_id=fspace, xfer_prp=dxpl)
         call h5sclose_f(mspace, error)
         call h5sclose_f(fspace, error)
         call h5dclose_f(dset, error)
         if (any(e /= 0)) then
            call set_error(status, STATUS_IO, path//":"//name//": cannot read this rank's columns")
            return
         end if
         map = transpose(stored)
      end subroutine read_map
   end subroutine read_columns
end module femcod_mpi_input
