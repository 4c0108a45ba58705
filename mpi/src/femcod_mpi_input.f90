!> femcod-mpi's input by slabs: an HDF5 deck (femcod_deck_h5) read by every rank, each its
!> own columns of both surfaces as hyperslabs of /lower and /upper, collectively (MPI-IO);
!> a text deck read by every rank, its own range of the file's bytes (femcod_deck_stream),
!> each height then sent to the rank of its column. The composite gaps are formed on the
!> ranks (femcod_scene's initial gaps, element by element, with the two maxima over all
!> ranks): no rank holds more than its columns (and, while a text deck is read, its
!> range's heights twice: read and packed). A height
!> file that is an HDF5 dataset (`--lower FILE.h5:/DATASET`, and `--upper` likewise) is
!> read by every rank, its own columns, with the height file's rules computed over the
!> ranks (units, finite values, the least-squares plane: removed with --remove-plane,
!> its tilt reported without). Other height files go through rank 0 (femcod_mpi_cg's
!> scatter_problem).
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
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_IO, STATUS_USAGE
   use femcod_problem, only: contact_problem, MAX_HEIGHT
   use femcod_deck_h5, only: read_deck_h5_header, is_hdf5_file
   use femcod_deck_stream, only: deck_stream, open_deck_stream, read_deck_heights, close_deck_stream, open_deck_range, &
      count_deck_range, separator_at_or_after, too_few_heights, binary_byte, balanced_cuts
   use femcod_generate, only: scene_spec, scene_header
   use femcod_heights, only: unit_in_nm
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_rank_and_dims
   use femcod_strings, only: string_type, int_str, sig_str, format_real
   use femcod_solver_options, only: cg_settings
   use femcod_mpi_cg, only: column_split, coarse_factor, problem_constants
   use femcod_mpi_results, only: agree
   implicit none
   private
   public :: read_deck_columns, read_text_deck_columns
   public :: is_dataset_scene, read_dataset_header, read_dataset_columns

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
   !> deck, read by every rank: rank 0 reads the header (in `problem`, on rank 0 only);
   !> each rank counts the heights and line ends of blocks of the bytes (each block from a
   !> separator), every rank learns every block, the ranges are cut between blocks for
   !> about equal work, and each rank reads its range (femcod_deck_stream, with the file's
   !> line and height numbers); an all-to-all takes each height to the rank of its column.
   !> Every message is read_deck's (file, line, what was expected), the first in the file
   !> if several ranks find one, a binary byte anywhere first. `constants` and `block` on
   !> every rank. Collective.
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
      real(dp), allocatable :: lower(:, :), upper(:, :), values(:)
      !> file: the heights' first byte, the file's size, the line at that byte, the last
      !> line of the header, 1 if the file ends with a line end. bytes: this rank's range.
      !> mine: the heights of this range; before, total: the heights and line ends of the
      !> ranges before it, of all. taken: the heights read here, and the first one's number.
      !> every: each block's first byte, heights, line ends and first binary byte (place,
      !> line ends before it, code), all ranks' in file order.
      integer, parameter :: BLOCKS = 16
      integer(i8) :: file(5), bytes(2), mine, before(2), total(2), taken(2)
      integer(i8), allocatable :: every(:, :), starts(:)
      integer, allocatable :: cuts(:)
      integer :: k
      integer(i8), allocatable :: first_height(:), takes(:)
      integer :: rank, ranks, np
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      allocate(local(0, 0))
      constants = 0
      block = 1
      file = 0
      if (rank == 0) then
         call open_deck_stream(path, stream, problem, status)
         if (status%code == 0) then
            constants = problem_constants(problem)
            file = [stream%next, stream%size, int(stream%line0, i8), int(stream%last_line, i8), 0_i8]
            if (last_byte_ends_line(stream)) file(5) = 1
         end if
         call close_deck_stream(stream)
      end if
      call agree(status, comm)
      if (status%code /= 0) return
      call MPI_Bcast(constants, 4, MPI_DOUBLE_PRECISION, 0, comm)
      call MPI_Bcast(file, 5, MPI_INTEGER8, 0, comm)
      np = nint(constants(1))
      block = coarse_factor(np, ranks, how)
      call column_split(np, ranks, block, first, count)
      ! Each rank counts BLOCKS blocks of an even share of the bytes (each block from the
      ! separator at or after its start); all ranks learn every block, and the ranges are
      ! cut between blocks for about even work: a height costs about as much as 6 of its
      ! bytes (fitted on a 4096^2 deck's two ranges, 22 ns a height and 3.8 ns a byte),
      ! and a rough surface's long numbers stand beside a flat one's short zeros.
      call count_blocks()
      call first_failure(status, comm)
      if (status%code /= 0) return
      call MPI_Allgather(MPI_IN_PLACE, 0, MPI_INTEGER8, every, 6*BLOCKS, MPI_INTEGER8, comm)
      starts = [every(1, :), file(2) + 1]
      allocate(cuts(0:ranks))
      cuts(:) = balanced_cuts(real(every(2, :), dp) + real(starts(2:) - starts(:size(starts) - 1), dp)/6, ranks)
      bytes = [starts(cuts(rank) + 1), starts(cuts(rank + 1) + 1) - 1]
      mine = sum(every(2, cuts(rank) + 1:cuts(rank + 1)))
      before = [sum(every(2, :cuts(rank))), sum(every(3, :cuts(rank)))]
      total = [sum(every(2, :)), sum(every(3, :))]
      ! A binary byte anywhere first (the file is no text deck), as read_deck.
      k = findloc(every(4, :) > 0, .true., dim=1)
      if (k > 0) then
         call set_error(status, STATUS_BAD_INPUT, binary_byte(path, int(file(3) + sum(every(3, :k - 1)) + &
            every(5, k)), int(every(6, k)), every(4, k)))
         return
      end if
      ! This range's heights up to the 2 NP^2th; the range that holds the one after it
      ! (if any) reports it as read_deck does.
      taken = [max(0_i8, min(mine, 2*int(np, i8)**2 - before(1))), before(1)]
      allocate(values(taken(1)))
      if (taken(1) > 0 .or. before(1) == 2*int(np, i8)**2) then
         call open_deck_range(path, np, bytes(1), bytes(2), int(file(3) + before(2)), before(1), stream, status)
         if (status%code == 0) call read_deck_heights(stream, values, status)
         call close_deck_stream(stream)
      end if
      call first_failure(status, comm)
      if (status%code /= 0) return
      if (total(1) < 2*int(np, i8)**2) then
         call set_error(status, STATUS_BAD_INPUT, too_few_heights(path, last_line(), np, total(1)))
         return
      end if
      allocate(first_height(0:ranks - 1), takes(0:ranks - 1))
      call MPI_Allgather(taken(2), 1, MPI_INTEGER8, first_height, 1, MPI_INTEGER8, comm)
      call MPI_Allgather(taken(1), 1, MPI_INTEGER8, takes, 1, MPI_INTEGER8, comm)
      call to_column_owners(values, first_height, takes, np, first, count, comm, lower, upper, status)
      if (status%code /= 0) return
      call composite_gaps(lower, upper, comm, local)
   contains
      !> This rank's BLOCKS blocks of its even share of the bytes, counted, into its
      !> columns of `every` (allocated here for all ranks).
      subroutine count_blocks()
         integer(i8) :: share(2), at(0:BLOCKS)
         integer :: b, c
         allocate(every(6, BLOCKS*ranks))
         every = 0
         call range_start(rank, share(1))
         call range_start(rank + 1, share(2))
         at(0) = share(1)
         at(BLOCKS) = share(2)
         do b = 1, BLOCKS - 1
            call separator_at_or_after(path, max(at(b - 1), share(1) + ((share(2) - share(1))*b)/BLOCKS), &
               share(2) - 1, at(b), status)
         end do
         do b = 1, BLOCKS
            c = rank*BLOCKS + b
            every(1, c) = at(b - 1)
            call count_deck_range(path, at(b - 1), at(b) - 1, every(2, c), every(3, c), every(4:6, c), status)
         end do
      end subroutine count_blocks
      !> The first byte of rank r's range (r = ranks: the byte after the file).
      subroutine range_start(r, at)
         integer, intent(in) :: r
         integer(i8), intent(out) :: at
         integer(i8) :: share
         if (r == 0) then
            at = file(1)
         else if (r >= ranks) then
            at = file(2) + 1
         else
            share = file(1) + ((file(2) - file(1) + 1)*r)/ranks
            call separator_at_or_after(path, share, file(2), at, status)
         end if
      end subroutine range_start
      !> The file's last line that holds anything (femcod_deck_stream's last_line).
      integer function last_line()
         last_line = int(file(4))
         if (file(2) >= file(1)) last_line = int(file(3) + total(2) - file(5))
      end function last_line
   end subroutine read_text_deck_columns

   !> Whether the file's last byte is a line end.
   logical function last_byte_ends_line(stream) result(ends)
      type(deck_stream), intent(in) :: stream
      character(len=1) :: last
      integer :: ios
      ends = .false.
      if (stream%size < 1 .or. stream%unit == -1) return
      read(stream%unit, pos=stream%size, iostat=ios) last
      ends = ios == 0 .and. last == new_line("a")
   end function last_byte_ends_line

   !> The first failing rank's status on every rank (the ranks read the file in order,
   !> so the first failing rank found the first fault in the file). Collective.
   subroutine first_failure(status, comm)
      type(status_type), intent(inout) :: status
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, ranks, who, code
      character(len=1024) :: message
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      who = merge(rank, ranks, status%code /= 0)
      call MPI_Allreduce(MPI_IN_PLACE, who, 1, MPI_INTEGER, MPI_MIN, comm)
      if (who == ranks) return
      code = status%code
      message = ""
      if (rank == who) message = status%message
      call MPI_Bcast(code, 1, MPI_INTEGER, who, comm)
      call MPI_Bcast(message, len(message), MPI_CHARACTER, who, comm)
      if (rank /= who) then
         status%code = 0
         call set_error(status, code, trim(message))
      end if
   end subroutine first_failure

   !> The heights `values` (in file order: the lower surface's NP^2 row by row, then the
   !> upper's; this rank's from number starts(rank) on, 0-based), each sent to the rank
   !> of its column (columns first(r) + 1 .. first(r) + count(r) on rank r), and freed:
   !> `lower` and `upper` (NP x count(rank)) from every rank's heights (starts, takes).
   !> Each range is walked by rows (a row's columns of one rank are one slice); what a
   !> rank receives, from the ranks in turn, is its columns of every row in file order.
   !> Collective.
   subroutine to_column_owners(values, starts, takes, np, first, count, comm, lower, upper, status)
      real(dp), allocatable, intent(inout) :: values(:)
      integer(i8), intent(in) :: starts(0:), takes(0:)
      integer, intent(in) :: np, first(0:), count(0:)
      type(MPI_Comm), intent(in) :: comm
      real(dp), allocatable, intent(out) :: lower(:, :), upper(:, :)
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: sent(:), received(:)
      integer(i8), allocatable :: send_n(:), recv_n(:)
      integer, allocatable :: send_counts(:), send_at(:), recv_counts(:), recv_at(:)
      integer(i8) :: k, row, t0, t1
      integer :: rank, ranks, r, ja, jb, lo, hi, n, i, i0, j
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      allocate(send_n(0:ranks - 1), recv_n(0:ranks - 1))
      do r = 0, ranks - 1
         send_n(r) = in_columns(starts(rank), takes(rank), first(r), count(r))
         recv_n(r) = in_columns(starts(r), takes(r), first(rank), count(rank))
      end do
      if (max(sum(send_n), sum(recv_n)) >= int(huge(1), i8)) then
         call set_error(status, STATUS_USAGE, "a text deck of "//int_str(np)//"^2 on "//int_str(ranks)// &
            " ranks: more than 2^31 heights a rank; use more ranks or an HDF5 deck (femcod mkdeck convert)")
      end if
      call first_failure(status, comm)
      if (status%code /= 0) return
      allocate(send_counts(0:ranks - 1), recv_counts(0:ranks - 1), send_at(0:ranks - 1), recv_at(0:ranks - 1))
      send_counts(:) = int(send_n)
      recv_counts(:) = int(recv_n)
      send_at(0) = 0
      recv_at(0) = 0
      do r = 1, ranks - 1
         send_at(r) = send_at(r - 1) + send_counts(r - 1)
         recv_at(r) = recv_at(r - 1) + recv_counts(r - 1)
      end do
      ! Packed for each rank in file order, row by row.
      allocate(sent(sum(send_n)))
      send_n = send_at
      t0 = starts(rank)
      t1 = t0 + takes(rank) - 1
      do row = t0/np, t1/np
         call row_columns(row, t0, t1, ja, jb)
         do r = 0, ranks - 1
            lo = max(ja, first(r) + 1)
            hi = min(jb, first(r) + count(r))
            if (hi < lo) cycle
            k = row*np + lo - 1 - t0
            sent(send_n(r) + 1:send_n(r) + hi - lo + 1) = values(k + 1:k + hi - lo + 1)
            send_n(r) = send_n(r) + hi - lo + 1
         end do
      end do
      deallocate(values)
      allocate(received(sum(recv_n)))
      call MPI_Alltoallv(sent, send_counts, send_at, MPI_DOUBLE_PRECISION, received, recv_counts, recv_at, &
         MPI_DOUBLE_PRECISION, comm)
      deallocate(sent)
      ! From each rank in turn, in file order: this rank's columns of each row, row after
      ! row (both surfaces' 2 NP rows), transposed by tiles of 64 rows.
      allocate(lower(np, count(rank)), upper(np, count(rank)))
      n = count(rank)
      !$omp parallel do private(j, i)
      do i0 = 1, np, 64
         do j = 1, n
            do i = i0, min(i0 + 63, np)
               lower(i, j) = received(int(i - 1, i8)*n + j)
               upper(i, j) = received(int(np + i - 1, i8)*n + j)
            end do
         end do
      end do
   contains
      !> The columns ja .. jb of row `row` (0-based over both surfaces) among heights
      !> t0 .. t1.
      pure subroutine row_columns(row, t0, t1, ja, jb)
         integer(i8), intent(in) :: row, t0, t1
         integer, intent(out) :: ja, jb
         ja = int(max(t0, row*np) - row*np) + 1
         jb = int(min(t1, row*np + np - 1) - row*np) + 1
      end subroutine row_columns
      !> Heights t0 .. t0 + n - 1 (0-based, file order) in columns c0 + 1 .. c0 + nc.
      pure integer(i8) function in_columns(t0, n, c0, nc) result(hits)
         integer(i8), intent(in) :: t0, n
         integer, intent(in) :: c0, nc
         integer(i8) :: row
         integer :: ja, jb
         hits = 0
         if (n <= 0 .or. nc <= 0) return
         do row = t0/np, (t0 + n - 1)/np
            call row_columns(row, t0, t0 + n - 1, ja, jb)
            hits = hits + max(0, min(jb, c0 + nc) - max(ja, c0 + 1) + 1)
         end do
      end function in_columns
   end subroutine to_column_owners

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
   !> hyperslab, collectively (read_dataset_part).
   subroutine read_columns(path, comm, np, j0, nj, lower, upper, status)
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, j0, nj
      real(dp), allocatable, intent(out) :: lower(:, :), upper(:, :)
      type(status_type), intent(inout) :: status
      allocate(lower(np, nj), upper(np, nj))
      call read_dataset_part(path, "/lower", comm, np, j0, nj, lower, status)
      if (status%code == 0) call read_dataset_part(path, "/upper", comm, np, j0, nj, upper, status)
   end subroutine read_columns
   !> Whether a scene is read by the ranks from HDF5 datasets: height files (a "matrix"
   !> scene) whose first, and second if any, is FILE.h5:/DATASET of an HDF5 file.
   logical function is_dataset_scene(spec) result(yes)
      type(scene_spec), intent(in) :: spec
      yes = .false.
      if (.not. allocated(spec%kind)) return
      if (spec%kind /= "matrix") return
      yes = is_dataset(spec%matrix_file)
      if (yes .and. allocated(spec%second_file)) then
         if (spec%second_file /= "") yes = is_dataset(spec%second_file)
      end if
   contains
      logical function is_dataset(path)
         character(len=*), intent(in) :: path
         integer :: colon
         colon = index(path, ":/", back=.true.)
         is_dataset = .false.
         if (colon > 1) is_dataset = is_hdf5_file(path(1:colon - 1))
      end function is_dataset
   end function is_dataset_scene

   !> Rank 0's look at a dataset scene before anything is read: each dataset two-
   !> dimensional and square (the second the first's size), a pixel given (--pixel: a
   !> dataset carries none), MAXCONT within NP^2; the problem's header (no heights) in
   !> `problem`, as femcod run's load_scene would make it.
   subroutine read_dataset_header(spec, problem, status)
      type(scene_spec), intent(in) :: spec
      type(contact_problem), intent(out) :: problem
      type(status_type), intent(inout) :: status
      integer :: np, other
      call dataset_side(spec%matrix_file, np, status)
      if (status%code /= 0) return
      if (allocated(spec%second_file)) then
         if (spec%second_file /= "") then
            call dataset_side(spec%second_file, other, status)
            if (status%code /= 0) return
            if (other /= np) then
               call set_error(status, STATUS_BAD_INPUT, spec%matrix_file//" has "//int_str(np)//" x "// &
                  int_str(np)//" heights, "//spec%second_file//" has "//int_str(other)//" x "//int_str(other)// &
                  ": the two surfaces must share one grid (femcod does not resample)")
               return
            end if
         end if
      end if
      if (.not. spec%pixel > 0) then
         call set_error(status, STATUS_USAGE, spec%matrix_file//" does not give its pixel size: give --pixel D (nm)")
         return
      end if
      if (spec%maxcont > np**2) then
         call set_error(status, STATUS_USAGE, "--maxcont "//int_str(spec%maxcont)//" is above the "// &
            int_str(np**2)//" pixels of "//spec%matrix_file//" (NP^2, the most contacts there are)")
         return
      end if
      call scene_header(spec, np, 0, problem, status)
   contains
      !> The side of the square dataset FILE:/DATASET (a message naming it otherwise).
      subroutine dataset_side(path, side, st)
         character(len=*), intent(in) :: path
         integer, intent(out) :: side
         type(status_type), intent(inout) :: st
         type(h5_file) :: file
         integer(i8) :: dims(7)
         integer :: colon, rank
         side = 0
         colon = index(path, ":/", back=.true.)
         call h5_open(path(1:colon - 1), file, st, STATUS_BAD_INPUT)
         call h5_rank_and_dims(file, path(colon + 1:), rank, dims, st, STATUS_BAD_INPUT)
         call h5_close(file, st)
         if (st%code /= 0) return
         if (rank /= 2) then
            call set_error(st, STATUS_BAD_INPUT, path//": expected a two-dimensional dataset of heights, found "// &
               int_str(rank)//" dimensions")
         else if (dims(1) /= dims(2)) then
            call set_error(st, STATUS_BAD_INPUT, path//": expected a square matrix of heights, found "// &
               int_str(int(dims(1)))//" rows of "//int_str(int(dims(2)))//" values")
         else if (dims(1) < 2 .or. dims(1) > 65536) then
            call set_error(st, STATUS_BAD_INPUT, path//": expected 2 to 65536 rows and columns, found "// &
               int_str(int(dims(1))))
         else
            side = int(dims(1))
         end if
      end subroutine dataset_side
   end subroutine read_dataset_header

   !> A dataset scene on the ranks of `comm`, as read_deck_columns gives an HDF5 deck:
   !> every rank reads its columns of each dataset (collective MPI-IO) and applies the
   !> height file's rules over all ranks: heights in --height-unit (nm by default),
   !> finite and within 1e12 nm; the least-squares plane removed with --remove-plane, its
   !> tilt reported without (more than 10 times the rms roughness about it, as femcod
   !> run); each surface from its lowest point; the other surface flat where there is no
   !> second dataset (--shape-on says which is which). `problem` (rank 0) is the header,
   !> `warnings` (rank 0) what femcod run would warn of. Collective.
   subroutine read_dataset_columns(spec, comm, how, problem, local, constants, block, status, warnings)
      type(scene_spec), intent(in) :: spec
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      type(contact_problem), intent(out) :: problem
      real(dp), allocatable, intent(out) :: local(:, :)
      real(dp), intent(out) :: constants(4)
      integer, intent(out) :: block
      type(status_type), intent(inout) :: status
      type(string_type), allocatable, intent(out) :: warnings(:)
      integer, allocatable :: first(:), count(:)
      real(dp), allocatable :: shape(:, :), other(:, :)
      integer :: rank, ranks, np
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      allocate(local(0, 0), warnings(0))
      constants = 0
      block = 1
      call read_dataset_header(spec, problem, status)
      call agree(status, comm)
      if (status%code /= 0) return
      np = problem%np
      constants = problem_constants(problem)
      block = coarse_factor(np, ranks, how)
      call column_split(np, ranks, block, first, count)
      call dataset_surface(spec, spec%matrix_file, comm, np, first(rank), count(rank), .true., shape, warnings, &
         status)
      if (status%code /= 0) return
      allocate(other(np, count(rank)))
      other = 0
      if (allocated(spec%second_file)) then
         if (spec%second_file /= "") call dataset_surface(spec, spec%second_file, comm, np, first(rank), &
            count(rank), .false., other, warnings, status)
      end if
      if (status%code /= 0) return
      if (spec%shape_on == "upper") then
         call composite_gaps(other, shape, comm, local)
      else
         call composite_gaps(shape, other, comm, local)
      end if
   end subroutine read_dataset_columns

   !> One dataset's columns j0 + 1 .. j0 + nj as a surface (nm, from its lowest point over
   !> all ranks), with the height file's checks over all ranks (femcod_heights'
   !> read_height_map and load_scene); the tilt is told of the first file only.
   !> Collective.
   subroutine dataset_surface(spec, path, comm, np, j0, nj, first_file, z, warnings, status)
      type(scene_spec), intent(in) :: spec
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, j0, nj
      logical, intent(in) :: first_file
      real(dp), allocatable, intent(inout) :: z(:, :)
      type(string_type), allocatable, intent(inout) :: warnings(:)
      type(status_type), intent(inout) :: status
      real(dp) :: scale, v(3), rise, roughness
      integer :: colon, bad
      colon = index(path, ":/", back=.true.)
      if (allocated(z)) deallocate(z)
      allocate(z(np, nj))
      call read_dataset_part(path(1:colon - 1), path(colon + 1:), comm, np, j0, nj, z, status)
      call agree(status, comm)
      if (status%code /= 0) return
      scale = 1
      if (spec%height_unit /= "") scale = unit_in_nm(spec%height_unit)
      if (abs(scale - 1) > 0) z = z*scale
      bad = 0
      if (.not. all(ieee_is_finite(z))) bad = 1
      call MPI_Allreduce(MPI_IN_PLACE, bad, 1, MPI_INTEGER, MPI_MAX, comm)
      if (bad == 1) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected finite heights (nm), found NaN or Inf")
         return
      end if
      ! v: the largest |z|, the largest z, minus the smallest z, over all ranks.
      v = -huge(1.0_dp)
      if (size(z) > 0) v = [maxval(abs(z)), maxval(z), -minval(z)]
      call MPI_Allreduce(MPI_IN_PLACE, v, 3, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      if (v(1) > MAX_HEIGHT) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected heights within 1e12 nm (1 km), found "// &
            format_real(v(1))//" nm (heights in other units: --height-unit)")
         return
      end if
      if (v(2) + v(3) > 0 .and. v(2) + v(3) < 1.0e-3_dp) warnings = [warnings, string_type(path// &
         ": the heights span only "//format_real(v(2) + v(3))//" nm; if the file holds metres, give --height-unit m")]
      if (first_file .and. .not. spec%plane) then
         call distributed_plane(z, np, j0, comm, .false., rise, roughness)
         if (rise > 10*roughness .and. roughness > 0) then
            warnings = [warnings, string_type(path//": its least-squares plane rises "//sig_str(rise, 3)// &
               " nm across the scan, "//sig_str(rise/roughness, 3)//" times the roughness about it ("// &
               sig_str(roughness, 3)//" nm rms): give --remove-plane if the tilt is the mounting, not the surface")]
         else if (rise > 0 .and. roughness == 0) then
            warnings = [warnings, string_type(path//": its heights are a tilted plane (rising "//sig_str(rise, 3)// &
               " nm across the scan) with no roughness about it")]
         end if
      end if
      if (spec%plane) call distributed_plane(z, np, j0, comm, .true., rise, roughness)
      v(1) = huge(1.0_dp)
      if (size(z) > 0) v(1) = minval(z)
      call MPI_Allreduce(MPI_IN_PLACE, v(1), 1, MPI_DOUBLE_PRECISION, MPI_MIN, comm)
      z = z - v(1)
   end subroutine dataset_surface

   !> femcod_surfaces' least-squares plane z = mz + b (i - mi) + c (j - mj) of the whole
   !> NP x NP grid, from this rank's columns j0 + 1 .. and sums over the ranks:
   !> subtracted (`remove`), or its rise across the grid and the rms about it (nm).
   !> Collective.
   subroutine distributed_plane(z, np, j0, comm, remove, rise, roughness)
      real(dp), intent(inout) :: z(:, :)
      integer, intent(in) :: np, j0
      type(MPI_Comm), intent(in) :: comm
      logical, intent(in) :: remove
      real(dp), intent(out) :: rise, roughness
      real(dp) :: sums(3), mi, mj, mz, b, c, deviations, r(1)
      integer :: i, j
      mi = (np + 1)/2.0_dp
      mj = (np + 1)/2.0_dp
      sums = [sum(z), 0.0_dp, 0.0_dp]
      call MPI_Allreduce(MPI_IN_PLACE, sums(1:1), 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      mz = sums(1)/real(np, dp)**2
      do j = 1, size(z, 2)
         do i = 1, np
            sums(2) = sums(2) + (z(i, j) - mz)*(i - mi)
            sums(3) = sums(3) + (z(i, j) - mz)*(j0 + j - mj)
         end do
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums(2:3), 2, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      ! The squared deviations of i (or j) over the full grid: NP columns of NP (NP^2 - 1)/12.
      deviations = real(np, dp)**2*(real(np, dp)**2 - 1)/12
      b = sums(2)/deviations
      c = sums(3)/deviations
      rise = abs(b)*(np - 1) + abs(c)*(np - 1)
      r = 0
      do j = 1, size(z, 2)
         do i = 1, np
            if (remove) then
               z(i, j) = z(i, j) - mz - b*(i - mi) - c*(j0 + j - mj)
            else
               r(1) = r(1) + (z(i, j) - mz - b*(i - mi) - c*(j0 + j - mj))**2
            end if
         end do
      end do
      roughness = 0
      if (.not. remove) then
         call MPI_Allreduce(MPI_IN_PLACE, r, 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
         roughness = sqrt(r(1)/real(np, dp)**2)
      end if
   end subroutine distributed_plane

   !> Columns j0 + 1 .. j0 + nj (all NP rows) of the dataset `name` of `path`, each rank
   !> its own hyperslab, collectively, as map(row, column) (the dataset in C order
   !> [row][column]). Collective.
   subroutine read_dataset_part(path, name, comm, np, j0, nj, map, status)
      character(len=*), intent(in) :: path, name
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, j0, nj
      real(dp), intent(out) :: map(:, :)
      type(status_type), intent(inout) :: status
      integer(hid_t) :: fapl, dxpl, fid, dset, fspace, mspace
      integer(hsize_t) :: block(2), offset(2)
      real(dp), allocatable :: stored(:, :)
      integer :: error, e(5)
      call h5open_f(error)
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, error)
      call h5pset_fapl_mpio_f(fapl, comm%MPI_VAL, MPI_INFO_NULL%MPI_VAL, error)
      call h5fopen_f(path, H5F_ACC_RDONLY_F, fid, error, access_prp=fapl)
      call h5pclose_f(fapl, error)
      if (error /= 0) then
         call set_error(status, STATUS_IO, path//": cannot open it on every rank (MPI-IO)")
         return
      end if
      call h5pcreate_f(H5P_DATASET_XFER_F, dxpl, error)
      call h5pset_dxpl_mpio_f(dxpl, H5FD_MPIO_COLLECTIVE_F, error)
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
      call h5pclose_f(dxpl, error)
      call h5fclose_f(fid, error)
      if (any(e /= 0)) then
         call set_error(status, STATUS_IO, path//":"//name//": cannot read this rank's columns")
         return
      end if
      map = transpose(stored)
   end subroutine read_dataset_part
end module femcod_mpi_input
