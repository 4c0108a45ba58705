!> A small, status-returning layer over the HDF5 Fortran API (HDF5 1.10, serial).
!>
!> Every routine first returns if `status` already holds an error, so a writer can
!> chain calls and test once. HDF5's own error stack printing is switched off; a
!> failure becomes `file:object: what failed` with code STATUS_IO (or STATUS_BAD_INPUT
!> when reading a file the user gave).
!>
!> Two-dimensional maps are stored so that C-order readers (h5py, h5dump) see
!> `data[i, j]` with i the row and j the column, as in the deck: the Fortran array
!> `map(i, j)` is written transposed.
module femcod_hdf5
   use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5dont_atexit_f, h5eset_auto_f, h5fcreate_f, h5fopen_f, h5fclose_f, &
      h5gcreate_f, h5gclose_f, h5screate_simple_f, h5screate_f, h5sclose_f, h5dcreate_f, h5dopen_f, h5dclose_f, &
      h5dwrite_f, h5dread_f, h5dget_space_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, &
      h5acreate_f, h5aopen_f, h5aclose_f, h5awrite_f, h5aread_f, h5oopen_f, h5oclose_f, h5tcopy_f, h5tset_size_f, &
      h5tclose_f, h5lexists_f, h5aexists_f, h5dget_type_f, h5tget_class_f, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, &
      H5F_ACC_RDWR_F, H5S_SCALAR_F, H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_FORTRAN_S1, H5T_INTEGER_F, H5T_FLOAT_F, &
      H5T_STRING_F, &
      H5T_COMPOUND_F, H5T_ENUM_F, H5T_C_S1, h5tset_cset_f, H5T_CSET_UTF8_F, h5tis_variable_str_f, h5aget_type_f, &
      h5pcreate_f, h5pclose_f, h5pset_chunk_f, h5pset_deflate_f, h5pset_shuffle_f, h5pset_virtual_f, &
      h5sselect_all_f, H5P_DATASET_CREATE_F, H5P_DEFAULT_F, h5sselect_hyperslab_f, H5S_SELECT_SET_F, &
      h5aget_space_f, h5sget_simple_extent_npoints_f
   use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_char, c_null_char, c_size_t, c_int, c_f_pointer, &
      c_associated, c_null_ptr, c_int64_t, c_int32_t, c_long, c_funptr, c_funloc
   use, intrinsic :: iso_fortran_env, only: int64
   use femcod_kinds, only: dp
   use femcod_zlib, only: c_compress2, c_compress_bound
   use femcod_status, only: status_type, set_error, STATUS_IO
   use femcod_strings, only: int_str
   use femcod_files, only: clear_write_error, write_error_cause
   implicit none
   private
   public :: h5_file, h5_create, h5_open, h5_reopen, h5_close, h5_group, h5_write, h5_attribute, h5_read, h5_exists
   public :: h5_read_string_attribute, h5_rank_and_dims, h5_flat_view

   !> An open HDF5 file and the name it was opened under (for messages).
   type :: h5_file
      integer(hid_t) :: id = -1
      character(len=:), allocatable :: path
   end type h5_file

   !> Write a dataset (scalar, 1-D or 2-D, real or integer) with a `units` attribute.
   interface h5_write
      module procedure write_real0, write_real1, write_real2, write_int0, write_int1, write_int2
   end interface h5_write

   !> Attach an attribute (string, real or integer scalar) to an existing object.
   interface h5_attribute
      module procedure attribute_string, attribute_real, attribute_int
   end interface h5_attribute

   !> Read a whole dataset (converted to double or integer by HDF5).
   interface h5_read
      module procedure read_real0, read_real1, read_real2, read_int0, read_int1
   end interface h5_read

   interface
      !> H5Tset_size with H5T_VARIABLE ((size_t) -1), which the Fortran API of 1.10 does
      !> not name.
      function c_h5tset_size(type_id, size) bind(c, name="H5Tset_size") result(rc)
         import :: c_int64_t, c_size_t, c_int
         !> hid_t, int64_t since HDF5 1.10
         integer(c_int64_t), value :: type_id
         integer(c_size_t), value :: size
         integer(c_int) :: rc
      end function c_h5tset_size
      function c_h5free_memory(mem) bind(c, name="H5free_memory") result(rc)
         import :: c_ptr, c_int
         type(c_ptr), value :: mem
         integer(c_int) :: rc
      end function c_h5free_memory
   end interface

   interface
      !> herr_t H5Dwrite_chunk(hid_t dset_id, hid_t dxpl_id, uint32_t filters,
      !>     const hsize_t *offset, size_t data_size, const void *buf): one chunk's bytes as
      !>     stored, past the filters (HDF5 1.10.3 and later; no Fortran wrapper in 1.10).
      function h5d_write_chunk(dset, dxpl, filters, offset, data_size, buf) bind(c, name="H5Dwrite_chunk") &
         result(rc)
         import :: hid_t, hsize_t, c_int32_t, c_size_t, c_char, c_int
         integer(hid_t), value :: dset, dxpl
         integer(c_int32_t), value :: filters
         integer(hsize_t), intent(in) :: offset(*)
         integer(c_size_t), value :: data_size
         character(kind=c_char), intent(in) :: buf(*)
         integer(c_int) :: rc
      end function h5d_write_chunk
   end interface

   !> h5_open's test read in a child process, bounded in seconds.
   integer(c_int), parameter :: PROBE_SECONDS = 10

   interface
      !> core/femcod_guarded.c: probe(arg) in a child process under an alarm; 0 it ended,
      !> 1 it failed or crashed, 2 the alarm stopped it, -1 no child (or under MPI).
      integer(c_int) function femcod_guarded(probe, arg, seconds) bind(C, name="femcod_guarded")
         import :: c_funptr, c_ptr, c_int
         type(c_funptr), value :: probe
         type(c_ptr), value :: arg
         integer(c_int), value :: seconds
      end function femcod_guarded
   end interface
contains

   !> Open the library. h5dont_atexit_f first (it fails harmlessly once the library is
   !> open): HDF5 1.10 crashes in its exit handler when a file's close failed (a full
   !> disk leaves the file in its table, HDFGroup/hdf5 #2291, fixed in 1.14.1). Every
   !> file here is closed explicitly, so the exit handler has nothing left to do.
   subroutine initialise()
      integer :: error
      call h5dont_atexit_f(error)
      call h5open_f(error)
      call h5eset_auto_f(0, error)
   end subroutine initialise

   !> Create (truncate) a file for writing.
   subroutine h5_create(path, file, status)
      character(len=*), intent(in) :: path
      type(h5_file), intent(out) :: file
      type(status_type), intent(inout) :: status
      call open_writable(path, .true., file, status)
   end subroutine h5_create

   !> Open an existing file read-only. `code` is the status code of a failure
   !> (STATUS_BAD_INPUT for a file the user gave).
   subroutine h5_open(path, file, status, code)
      character(len=*), intent(in) :: path
      type(h5_file), intent(out) :: file
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer :: error
      character(kind=c_char, len=:), allocatable, target :: c_path
      if (status%code /= 0) return
      call initialise()
      file%path = path
      file%id = -1
      ! The strings femcod reads, read first in a child process (core/femcod_guarded.c):
      ! libhdf5 can crash or loop on a corrupt file's string heap, and then only the
      ! child goes (the fuzz of issue 47: 6 of 400 mutated HDF5 decks).
      c_path = path//c_null_char
      select case (femcod_guarded(c_funloc(probe_strings), c_loc(c_path), PROBE_SECONDS))
      case (1)
         call set_error(status, code, path//": a corrupt HDF5 file (the HDF5 library failed reading its "// &
            "attributes in a test read); not read")
         return
      case (2)
         call set_error(status, code, path//": a corrupt HDF5 file (a test read of its attributes did not end "// &
            "in "//int_str(int(PROBE_SECONDS))//" s); not read")
         return
      end select
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file%id, error)
      if (error /= 0) then
         call set_error(status, code, path//": not a readable HDF5 file (missing, truncated or corrupted)")
         file%id = -1
      end if
   end subroutine h5_open

   !> Open, for reading and writing, a file this run created itself (a temporary it is
   !> still building): no test read first, as h5_open makes of the files a user gives.
   subroutine h5_reopen(path, file, status)
      character(len=*), intent(in) :: path
      type(h5_file), intent(out) :: file
      type(status_type), intent(inout) :: status
      call open_writable(path, .false., file, status)
   end subroutine h5_reopen

   !> h5_create (`create`) and h5_reopen: the file for writing, or the disk's reason why not.
   subroutine open_writable(path, create, file, status)
      character(len=*), intent(in) :: path
      logical, intent(in) :: create
      type(h5_file), intent(out) :: file
      type(status_type), intent(inout) :: status
      integer :: error
      character(len=:), allocatable :: cause
      if (status%code /= 0) return
      call initialise()
      file%path = path
      call clear_write_error()
      if (create) then
         call h5fcreate_f(path, H5F_ACC_TRUNC_F, file%id, error)
      else
         call h5fopen_f(path, H5F_ACC_RDWR_F, file%id, error)
      end if
      if (error /= 0) then
         cause = write_error_cause()
         if (len(cause) == 0 .and. create) cause = " (directory missing or not writable)"
         call set_error(status, STATUS_IO, path//": cannot "//trim(merge("create", "open  ", create))// &
            " the HDF5 file"//cause)
         file%id = -1
      end if
   end subroutine open_writable

   !> The test read of h5_open, in the child: every string attribute femcod reads (the
   !> deck's, the checkpoint's and a result set's), through h5_read_string_attribute's own
   !> checks. 0 when it ended (whatever it found: the parent reports that itself).
   integer(c_int) function probe_strings(arg) bind(C)
      type(c_ptr), value :: arg
      character(len=*), parameter :: OBJECTS(7) = [character(len=8) :: "/", "/", "/", "/run", "/run", "/deck", &
         "/options"]
      character(len=*), parameter :: KEYS(7) = [character(len=14) :: "format", "label", "femcod_version", &
         "femcod_version", "fingerprint", "label", "history"]
      type(h5_file) :: file
      type(status_type) :: local
      character(len=:), allocatable :: value
      integer :: k, error
      logical :: exists
      probe_strings = 0
      file%path = c_text(arg, 65536)
      call h5fopen_f(file%path, H5F_ACC_RDONLY_F, file%id, error)
      if (error /= 0) return
      do k = 1, size(KEYS)
         exists = trim(OBJECTS(k)) == "/"
         if (.not. exists) call h5lexists_f(file%id, trim(OBJECTS(k)), exists, error)
         if (.not. exists .or. error /= 0) cycle
         local = status_type()
         call h5_read_string_attribute(file, trim(OBJECTS(k)), trim(KEYS(k)), 65536, value, local, 3)
      end do
      call h5fclose_f(file%id, error)
   end function probe_strings

   !> Close the file (also after an error; then nothing is reported).
   subroutine h5_close(file, status)
      type(h5_file), intent(inout) :: file
      type(status_type), intent(inout) :: status
      integer :: error
      if (file%id < 0) return
      call h5fclose_f(file%id, error)
      file%id = -1
      if (error /= 0 .and. status%code == 0) call set_error(status, STATUS_IO, &
         file%path//": error closing the file"//write_error_cause())
   end subroutine h5_close

   !> Create a group (its parent must exist).
   subroutine h5_group(file, name, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      type(status_type), intent(inout) :: status
      integer(hid_t) :: group
      integer :: error
      if (status%code /= 0) return
      call h5gcreate_f(file%id, name, group, error)
      if (error /= 0) then
         call set_error(status, STATUS_IO, file%path//":"//name//": cannot create the group"//write_error_cause())
         return
      end if
      call h5gclose_f(group, error)
   end subroutine h5_group

   !> Whether a link (group or dataset) exists; every parent of `name` must exist.
   logical function h5_exists(file, name)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer :: error
      h5_exists = .false.
      if (file%id < 0) return
      call h5lexists_f(file%id, name, h5_exists, error)
      if (error /= 0) h5_exists = .false.
   end function h5_exists

   ! ---- writing ------------------------------------------------------------------

   !> Create the dataset `name` of the given type and shape (`dims` in Fortran order;
   !> empty: scalar) and return it open.
   subroutine create_dataset(file, name, dtype, dims, dset, status, compress)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: dtype
      integer(hsize_t), intent(in) :: dims(:)
      integer(hid_t), intent(out) :: dset
      type(status_type), intent(inout) :: status
      !> Chunked, byte-shuffled and deflated (level 1): for regular data such as a mesh.
      logical, intent(in), optional :: compress
      integer(hid_t) :: space, dcpl
      integer(hsize_t) :: chunk(size(dims))
      integer :: error
      dset = -1
      dcpl = H5P_DEFAULT_F
      if (present(compress)) then
         if (compress .and. size(dims) > 0 .and. product(dims) > 0) then
            chunk = dims
            if (by_column(dims)) chunk(1) = 1
            chunk(size(dims)) = chunk_rows(dims)
            call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl, error)
            call h5pset_chunk_f(dcpl, size(dims), chunk, error)
            call h5pset_shuffle_f(dcpl, error)
            call h5pset_deflate_f(dcpl, 1, error)
         end if
      end if
      if (size(dims) == 0) then
         call h5screate_f(H5S_SCALAR_F, space, error)
      else
         call h5screate_simple_f(size(dims), dims, space, error)
      end if
      if (error /= 0) then
         call set_error(status, STATUS_IO, file%path//":"//name//": cannot create the dataspace"//write_error_cause())
         return
      end if
      call h5dcreate_f(file%id, name, dtype, space, dset, error, dcpl_id=dcpl)
      call h5sclose_f(space, error)
      if (dcpl /= H5P_DEFAULT_F) call h5pclose_f(dcpl, error)
      if (dset < 0) then
         call set_error(status, STATUS_IO, file%path//":"//name//": cannot create the dataset"//write_error_cause())
      end if
   end subroutine create_dataset

   !> Rows of a compressed dataset's chunk (C order: its slowest dimension, Fortran's
   !> last; `dims` in Fortran order): about 2**17 values (1 MiB of doubles), of one
   !> column (by_column) or of whole rows (row_block).
   pure integer(hsize_t) function chunk_rows(dims)
      integer(hsize_t), intent(in) :: dims(:)
      if (by_column(dims)) then
         chunk_rows = min(dims(2), 131072_hsize_t)
      else
         chunk_rows = row_block(dims)
      end if
   end function chunk_rows

   !> Whole rows of about 2**17 values: a compressed map's chunk, and the block in which a
   !> plain map is transposed and written.
   pure integer(hsize_t) function row_block(dims)
      integer(hsize_t), intent(in) :: dims(:)
      row_block = min(dims(size(dims)), max(1_hsize_t, 131072_hsize_t/max(1_hsize_t, product(dims(1:size(dims) - 1)))))
   end function row_block

   !> Whether a compressed table of at most 8 columns (the mesh's nodes and
   !> quadrilaterals) is chunked by column: one column's values alone are far more
   !> regular than rows of interleaved columns. The 2048^2 mesh's nodes deflate in half
   !> the time to a tenth of the size (0.6 instead of 5.8 MB).
   pure logical function by_column(dims)
      integer(hsize_t), intent(in) :: dims(:)
      by_column = .false.
      if (size(dims) == 2) by_column = dims(1) <= 8
   end function by_column

   !> The whole of the open dataset `dset`, created with `compress` (chunked, shuffled,
   !> deflated), from `real_map` or `int_map` (one of them), stored transposed so that
   !> C-order readers see map(i, j) at [i - 1, j - 1]; `dims` as create_dataset had them.
   !> Each chunk (whole rows of the map, or rows of one column: by_column) is copied into
   !> the thread's buffer (rows transposed), shuffled (byte b of every value together:
   !> HDF5's shuffle filter) and deflated at level 1 (zlib's compress2: HDF5's deflate
   !> filter) on all threads, then handed to HDF5 as it is stored, in order
   !> (H5Dwrite_chunk, filter mask 0: every filter applied). HDF5 runs its filters on one
   !> thread: the 2048^2 mesh took 0.38 s that way. `error` /= 0 if zlib or HDF5 failed.
   subroutine write_deflated(dset, dims, error, real_map, int_map)
      integer(hid_t), intent(in) :: dset
      integer(hsize_t), intent(in) :: dims(2)
      integer, intent(out) :: error
      real(dp), intent(in), optional :: real_map(:, :)
      integer, intent(in), optional :: int_map(:, :)
      type :: deflated_chunk
         character(kind=c_char), allocatable :: z(:)
      end type deflated_chunk
      type(deflated_chunk), allocatable :: chunks(:)
      real(dp), allocatable, target :: real_rows(:, :)
      integer, allocatable, target :: int_rows(:, :)
      character(kind=c_char), pointer :: raw(:)
      character(kind=c_char), allocatable :: shuffled(:), z(:)
      logical, allocatable :: failed(:)
      integer(hsize_t) :: per_chunk, offset(2)
      integer(int64) :: chunk_bytes, values
      integer(c_long) :: bound, zlen
      integer :: nchunks, row_chunks, columns, k, b, elem, r0, nr, c, c0, j
      logical :: one_column
      per_chunk = chunk_rows(dims)
      one_column = by_column(dims)
      ! Columns in a chunk; chunk k holds rows r0 + 1.. of column c (all columns: c = 1).
      columns = int(merge(1_hsize_t, dims(1), one_column))
      elem = 8
      if (present(int_map)) elem = storage_size(0)/8
      values = columns*per_chunk
      chunk_bytes = elem*values
      row_chunks = int((dims(2) + per_chunk - 1)/per_chunk)
      nchunks = row_chunks*int(merge(dims(1), 1_hsize_t, one_column))
      bound = c_compress_bound(int(chunk_bytes, c_long))
      allocate(chunks(nchunks), failed(nchunks))
      !$omp parallel private(real_rows, int_rows, raw, shuffled, z, k, b, zlen, r0, nr, c, c0, j)
      if (present(int_map)) then
         allocate(int_rows(columns, per_chunk))
         call c_f_pointer(c_loc(int_rows), raw, [chunk_bytes])
      else
         allocate(real_rows(columns, per_chunk))
         call c_f_pointer(c_loc(real_rows), raw, [chunk_bytes])
      end if
      allocate(shuffled(chunk_bytes), z(bound))
      !$omp do schedule(dynamic)
      do k = 1, nchunks
         call chunk_place(k, r0, nr, c)
         ! Columns c0 + 1 .. c0 + columns of the rows, transposed. The last chunk is
         ! stored whole: its part beyond the rows is never read.
         c0 = merge(c, 1, one_column) - 1
         if (present(int_map)) then
            do j = 1, columns
               int_rows(j, 1:nr) = int_map(r0 + 1:r0 + nr, c0 + j)
            end do
            int_rows(:, nr + 1:) = 0
         else
            do j = 1, columns
               real_rows(j, 1:nr) = real_map(r0 + 1:r0 + nr, c0 + j)
            end do
            real_rows(:, nr + 1:) = 0
         end if
         do b = 1, elem
            shuffled((b - 1)*values + 1:b*values) = raw(b::elem)
         end do
         zlen = bound
         failed(k) = c_compress2(z, zlen, shuffled, int(chunk_bytes, c_long), 1_c_int) /= 0
         chunks(k)%z = z(1:zlen)
      end do
      !$omp end do
      !$omp end parallel
      error = merge(1, 0, any(failed))
      do k = 1, nchunks
         if (error /= 0) exit
         call chunk_place(k, r0, nr, c)
         ! C order: [row, column].
         offset = [int(r0, hsize_t), int(merge(c - 1, 0, one_column), hsize_t)]
         if (h5d_write_chunk(dset, H5P_DEFAULT_F, 0_c_int32_t, offset, size(chunks(k)%z, kind=c_size_t), &
            chunks(k)%z) < 0) error = 1
      end do
   contains
      !> Chunk k's first row r0 + 1, its rows nr within the map, and its column c.
      pure subroutine chunk_place(k, r0, nr, c)
         integer, intent(in) :: k
         integer, intent(out) :: r0, nr, c
         c = (k - 1)/row_chunks + 1
         r0 = int(mod(k - 1, row_chunks)*per_chunk)
         nr = int(min(per_chunk, dims(2) - r0))
      end subroutine chunk_place
   end subroutine write_deflated

   !> Whether the optional `compress` is present and true.
   pure logical function compressed(compress)
      logical, intent(in), optional :: compress
      compressed = .false.
      if (present(compress)) compressed = compress
   end function compressed

   !> Close a dataset after writing; attach its units.
   subroutine finish_dataset(file, name, dset, error, units, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      integer(hid_t), intent(inout) :: dset
      integer, intent(in) :: error
      type(status_type), intent(inout) :: status
      integer :: e
      call h5dclose_f(dset, e)
      if (error /= 0) then
         call set_error(status, STATUS_IO, file%path//":"//name//": cannot write the dataset"//write_error_cause())
         return
      end if
      call h5_attribute(file, name, "units", units, status)
   end subroutine finish_dataset

   !> A new dataset `name` of HDF5 type `dtype` and shape `dims` (Fortran order; empty: a
   !> scalar) from the contiguous values at `buffer`, with its units: every scalar and 1-D
   !> write below.
   subroutine write_plain(file, name, dtype, dims, buffer, units, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      integer(hid_t), intent(in) :: dtype
      integer(hsize_t), intent(in) :: dims(:)
      type(c_ptr), intent(in) :: buffer
      type(status_type), intent(inout) :: status
      integer(hid_t) :: dset
      integer :: error
      if (status%code /= 0) return
      call create_dataset(file, name, dtype, dims, dset, status)
      if (status%code /= 0) return
      call h5dwrite_f(dset, dtype, buffer, error)
      call finish_dataset(file, name, dset, error, units, status)
   end subroutine write_plain

   subroutine write_real0(file, name, value, units, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      real(dp), intent(in), target :: value
      type(status_type), intent(inout) :: status
      call write_plain(file, name, H5T_NATIVE_DOUBLE, [integer(hsize_t) ::], c_loc(value), units, status)
   end subroutine write_real0

   subroutine write_real1(file, name, values, units, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      real(dp), intent(in), target, contiguous :: values(:)
      type(status_type), intent(inout) :: status
      call write_plain(file, name, H5T_NATIVE_DOUBLE, [size(values, kind=hsize_t)], c_loc(values), units, status)
   end subroutine write_real1

   !> A map(i, j) (row i, column j), stored so that C-order readers see [i, j].
   subroutine write_real2(file, name, map, units, status, compress)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      real(dp), intent(in) :: map(:, :)
      type(status_type), intent(inout) :: status
      !> Chunked and deflated (create_dataset).
      logical, intent(in), optional :: compress
      integer(hid_t) :: dset, filespace, memspace
      integer(hsize_t) :: dims(2), block(2)
      real(dp), allocatable :: stored(:, :)
      integer :: error, e, rows, r0, nr
      if (status%code /= 0) return
      dims = [size(map, 2, kind=hsize_t), size(map, 1, kind=hsize_t)]
      call create_dataset(file, name, H5T_NATIVE_DOUBLE, dims, dset, status, compress)
      if (status%code /= 0) return
      if (compressed(compress) .and. size(map) > 0) then
         call write_deflated(dset, dims, error, real_map=map)
      else if (size(map) == 0) then
         allocate(stored(size(map, 2), size(map, 1)))
         call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, stored, dims, error)
      else
         ! In blocks of whole rows (about 1 MiB), each transposed into the same buffer:
         ! no second copy of the map in fresh memory.
         rows = int(row_block(dims))
         allocate(stored(size(map, 2), rows))
         call h5dget_space_f(dset, filespace, error)
         if (error == 0) then
            do r0 = 1, size(map, 1), rows
               nr = min(rows, size(map, 1) - r0 + 1)
               call transpose_into(map(r0:r0 + nr - 1, :), stored(:, 1:nr))
               block = [dims(1), int(nr, hsize_t)]
               call h5screate_simple_f(2, block, memspace, e)
               if (e == 0) call h5sselect_hyperslab_f(filespace, H5S_SELECT_SET_F, [0_hsize_t, int(r0 - 1, hsize_t)], &
                  block, e)
               if (e == 0) call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, stored(:, 1:nr), block, e, mem_space_id=memspace, &
                  file_space_id=filespace)
               call h5sclose_f(memspace, error)
               error = e
               if (error /= 0) exit
            end do
            call h5sclose_f(filespace, e)
         end if
      end if
      call finish_dataset(file, name, dset, error, units, status)
   end subroutine write_real2

   subroutine write_int0(file, name, value, units, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      integer, intent(in), target :: value
      type(status_type), intent(inout) :: status
      call write_plain(file, name, H5T_NATIVE_INTEGER, [integer(hsize_t) ::], c_loc(value), units, status)
   end subroutine write_int0

   subroutine write_int1(file, name, values, units, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      integer, intent(in), target, contiguous :: values(:)
      type(status_type), intent(inout) :: status
      call write_plain(file, name, H5T_NATIVE_INTEGER, [size(values, kind=hsize_t)], c_loc(values), units, status)
   end subroutine write_int1

   subroutine write_int2(file, name, map, units, status, compress)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, units
      integer, intent(in) :: map(:, :)
      type(status_type), intent(inout) :: status
      !> Chunked and deflated (create_dataset).
      logical, intent(in), optional :: compress
      integer(hid_t) :: dset
      integer(hsize_t) :: dims(2)
      integer, allocatable :: stored(:, :)
      integer :: error
      if (status%code /= 0) return
      dims = [size(map, 2, kind=hsize_t), size(map, 1, kind=hsize_t)]
      call create_dataset(file, name, H5T_NATIVE_INTEGER, dims, dset, status, compress)
      if (status%code /= 0) return
      if (compressed(compress) .and. size(map) > 0) then
         call write_deflated(dset, dims, error, int_map=map)
      else
         allocate(stored(size(map, 2), size(map, 1)))
         stored(:, :) = transpose(map)
         call h5dwrite_f(dset, H5T_NATIVE_INTEGER, stored, dims, error)
      end if
      call finish_dataset(file, name, dset, error, units, status)
   end subroutine write_int2

   ! ---- attributes ---------------------------------------------------------------

   !> A one-dimensional virtual dataset `name` that shows the two-dimensional dataset
   !> `source` of the same file row after row (C order: data[i, j] at i*ncols + j), for
   !> readers that want cell data as a list (XDMF through meshio). No data is copied.
   subroutine h5_flat_view(file, name, source, units, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, source, units
      type(status_type), intent(inout) :: status
      integer(hid_t) :: dset, vspace, sspace, dcpl
      integer(hsize_t) :: dims(2), maxdims(2), flat(1)
      integer :: error, rank
      if (status%code /= 0) return
      call h5dopen_f(file%id, source, dset, error)
      if (error /= 0) then
         call set_error(status, STATUS_IO, file%path//":"//source//": no such dataset for "//name)
         return
      end if
      call h5dget_space_f(dset, sspace, error)
      call h5dclose_f(dset, error)
      call h5sget_simple_extent_ndims_f(sspace, rank, error)
      call h5sget_simple_extent_dims_f(sspace, dims, maxdims, error)
      flat = product(dims(1:rank))
      call h5sselect_all_f(sspace, error)
      call h5screate_simple_f(1, flat, vspace, error)
      call h5sselect_all_f(vspace, error)
      call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl, error)
      ! "." is this file.
      call h5pset_virtual_f(dcpl, vspace, ".", source, sspace, error)
      call h5sclose_f(sspace, error)
      if (error /= 0) then
         call h5sclose_f(vspace, error)
         call h5pclose_f(dcpl, error)
         call set_error(status, STATUS_IO, file%path//":"//name//": cannot map the view onto "//source)
         return
      end if
      call h5dcreate_f(file%id, name, H5T_NATIVE_DOUBLE, vspace, dset, error, dcpl_id=dcpl)
      call h5sclose_f(vspace, error)
      call h5pclose_f(dcpl, error)
      if (dset < 0) then
         call set_error(status, STATUS_IO, file%path//":"//name//": cannot create the view"//write_error_cause())
         return
      end if
      call finish_dataset(file, name, dset, 0, units, status)
   end subroutine h5_flat_view

   !> Open object `name` and create attribute `key` of type `dtype` (scalar).
   subroutine create_attribute(file, name, key, dtype, object, attr, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, key
      integer(hid_t), intent(in) :: dtype
      integer(hid_t), intent(out) :: object, attr
      type(status_type), intent(inout) :: status
      integer(hid_t) :: space
      integer :: error
      attr = -1
      call h5oopen_f(file%id, name, object, error)
      if (error /= 0) then
         call set_error(status, STATUS_IO, file%path//":"//name//": no such object for attribute "//key)
         return
      end if
      call h5screate_f(H5S_SCALAR_F, space, error)
      call h5acreate_f(object, key, dtype, space, attr, error)
      call h5sclose_f(space, error)
      if (error /= 0) then
         call h5oclose_f(object, error)
         call set_error(status, STATUS_IO, file%path//":"//name//": cannot create attribute "//key//write_error_cause())
      end if
   end subroutine create_attribute

   subroutine close_attribute(file, name, key, object, attr, error, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, key
      integer(hid_t), intent(inout) :: object, attr
      integer, intent(in) :: error
      type(status_type), intent(inout) :: status
      integer :: e
      call h5aclose_f(attr, e)
      call h5oclose_f(object, e)
      if (error /= 0) call set_error(status, STATUS_IO, &
         file%path//":"//name//": cannot write attribute "//key//write_error_cause())
   end subroutine close_attribute

   !> A variable-length UTF-8 string attribute: h5py returns it as str, h5dump shows it
   !> without padding.
   subroutine attribute_string(file, name, key, value, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, key, value
      type(status_type), intent(inout) :: status
      integer(hid_t) :: object, attr, stype
      character(kind=c_char, len=:), allocatable, target :: text
      type(c_ptr), target :: pointer
      integer :: error
      if (status%code /= 0) return
      call variable_string_type(stype)
      call create_attribute(file, name, key, stype, object, attr, status)
      if (status%code /= 0) then
         call h5tclose_f(stype, error)
         return
      end if
      text = value//c_null_char
      pointer = c_loc(text)
      call h5awrite_f(attr, stype, c_loc(pointer), error)
      call h5tclose_f(stype, error)
      call close_attribute(file, name, key, object, attr, error, status)
   end subroutine attribute_string

   !> A new variable-length UTF-8 C string type (close it with h5tclose_f).
   subroutine variable_string_type(stype)
      integer(hid_t), intent(out) :: stype
      integer :: error
      call h5tcopy_f(H5T_C_S1, stype, error)
      error = c_h5tset_size(stype, -1_c_size_t)
      call h5tset_cset_f(stype, H5T_CSET_UTF8_F, error)
   end subroutine variable_string_type

   !> A scalar attribute of HDF5 type `dtype` from the value at `buffer`.
   subroutine attribute_plain(file, name, key, dtype, buffer, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, key
      integer(hid_t), intent(in) :: dtype
      type(c_ptr), intent(in) :: buffer
      type(status_type), intent(inout) :: status
      integer(hid_t) :: object, attr
      integer :: error
      if (status%code /= 0) return
      call create_attribute(file, name, key, dtype, object, attr, status)
      if (status%code /= 0) return
      call h5awrite_f(attr, dtype, buffer, error)
      call close_attribute(file, name, key, object, attr, error, status)
   end subroutine attribute_plain

   subroutine attribute_real(file, name, key, value, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, key
      real(dp), intent(in), target :: value
      type(status_type), intent(inout) :: status
      call attribute_plain(file, name, key, H5T_NATIVE_DOUBLE, c_loc(value), status)
   end subroutine attribute_real

   subroutine attribute_int(file, name, key, value, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, key
      integer, intent(in), target :: value
      type(status_type), intent(inout) :: status
      call attribute_plain(file, name, key, H5T_NATIVE_INTEGER, c_loc(value), status)
   end subroutine attribute_int

   !> Read a string attribute of at most `length` characters (variable or fixed length).
   subroutine h5_read_string_attribute(file, name, key, length, value, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name, key
      integer, intent(in) :: length, code
      character(len=:), allocatable, intent(out) :: value
      type(status_type), intent(inout) :: status
      integer(hid_t) :: object, attr, stype, ftype, space
      integer(hsize_t) :: none(0), npoints
      integer :: error, error2, type_class
      logical :: exists, variable
      type(c_ptr), target :: pointer
      type(c_ptr) :: buffer
      value = ""
      if (status%code /= 0) return
      call h5oopen_f(file%id, name, object, error)
      if (error /= 0) then
         call set_error(status, code, file%path//":"//name//": missing")
         return
      end if
      call h5aexists_f(object, key, exists, error)
      if (.not. exists .or. error /= 0) then
         call h5oclose_f(object, error)
         call set_error(status, code, file%path//":"//name//": attribute "//key//" missing")
         return
      end if
      call h5aopen_f(object, key, attr, error)
      ! One string, and nothing else, before a byte is read: a corrupt file may declare
      ! another class or many elements, which would be read past the one string's buffer
      ! (a segfault, or minutes of conversions: the fuzz of issue 47).
      npoints = 0
      type_class = -1
      call h5aget_space_f(attr, space, error)
      if (error == 0) then
         call h5sget_simple_extent_npoints_f(space, npoints, error)
         call h5sclose_f(space, error2)
      end if
      call h5aget_type_f(attr, ftype, error)
      if (error == 0) call h5tget_class_f(ftype, type_class, error)
      if (error /= 0 .or. npoints /= 1 .or. type_class /= H5T_STRING_F) then
         call h5tclose_f(ftype, error2)
         call h5aclose_f(attr, error2)
         call h5oclose_f(object, error2)
         call set_error(status, code, file%path//":"//name//": attribute "//key//" is not one string (a corrupt "// &
            "or foreign file)")
         return
      end if
      variable = .false.
      if (error == 0) call h5tis_variable_str_f(ftype, variable, error)
      call h5tclose_f(ftype, error)
      if (variable) then
         ! Variable length (femcod from 2026-11): the library allocates the text.
         call variable_string_type(stype)
         pointer = c_null_ptr
         buffer = c_loc(pointer)
         call h5aread_f(attr, stype, buffer, error)
         if (error == 0 .and. c_associated(pointer)) then
            value = c_text(pointer, length)
            error = c_h5free_memory(pointer)
            error = 0
         end if
      else
         ! Fixed length, blank-padded (earlier files and checkpoints).
         call h5tcopy_f(H5T_FORTRAN_S1, stype, error)
         call h5tset_size_f(stype, int(length, size_t), error)
         deallocate(value)
         allocate(character(len=length) :: value)
         call h5aread_f(attr, stype, value, none, error)
         value = trim(value)
      end if
      call h5tclose_f(stype, error2)
      call h5aclose_f(attr, error2)
      call h5oclose_f(object, error2)
      if (error /= 0) then
         call set_error(status, code, file%path//":"//name//": cannot read attribute "//key)
         return
      end if
   end subroutine h5_read_string_attribute

   ! ---- reading ------------------------------------------------------------------

   !> Rank and dimensions of a dataset, in C order (dims(1) the slowest index: rows).
   subroutine h5_rank_and_dims(file, name, rank, dims, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer, intent(out) :: rank
      integer(hsize_t), intent(out) :: dims(7)
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer(hid_t) :: dset, space
      integer(hsize_t) :: fdims(7), maxdims(7)
      integer :: error
      rank = -1
      dims = 0
      if (status%code /= 0) return
      call open_dataset(file, name, dset, status, code)
      if (status%code /= 0) return
      call h5dget_space_f(dset, space, error)
      call h5sget_simple_extent_ndims_f(space, rank, error)
      if (rank >= 0 .and. rank <= 7) then
         call h5sget_simple_extent_dims_f(space, fdims(1:rank), maxdims(1:rank), error)
         dims(1:rank) = fdims(rank:1:-1)
      end if
      call h5sclose_f(space, error)
      call h5dclose_f(dset, error)
   end subroutine h5_rank_and_dims

   subroutine open_dataset(file, name, dset, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer(hid_t), intent(out) :: dset
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer :: error
      dset = -1
      if (.not. dataset_path_exists(file, name)) then
         call set_error(status, code, file%path//":"//name//": no such dataset")
         return
      end if
      call h5dopen_f(file%id, name, dset, error)
      if (error /= 0) call set_error(status, code, file%path//":"//name//": cannot open the dataset")
   end subroutine open_dataset

   !> Whether every component of an absolute or relative path exists.
   logical function dataset_path_exists(file, name)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer :: k
      dataset_path_exists = .false.
      if (len_trim(name) == 0) return
      do k = 2, len(name)
         if (name(k:k) == "/") then
            if (.not. h5_exists(file, name(1:k - 1))) return
         end if
      end do
      dataset_path_exists = h5_exists(file, name)
   end function dataset_path_exists

   !> Check rank and type (integers or floating point only), then open for reading.
   subroutine read_checked(file, name, rank_wanted, dset, fdims, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer, intent(in) :: rank_wanted, code
      integer(hid_t), intent(out) :: dset
      integer(hsize_t), intent(out) :: fdims(7)
      type(status_type), intent(inout) :: status
      integer :: rank, type_class, error
      integer(hsize_t) :: dims(7)
      integer(hid_t) :: dtype
      dset = -1
      call h5_rank_and_dims(file, name, rank, dims, status, code)
      if (status%code /= 0) return
      if (rank /= rank_wanted) then
         call set_error(status, code, file%path//":"//name//": expected a dataset of rank "// &
            char(48 + rank_wanted)//", found rank "//char(48 + max(0, min(rank, 9))))
         return
      end if
      fdims = 0
      fdims(1:rank) = dims(rank:1:-1)
      call open_dataset(file, name, dset, status, code)
      if (status%code /= 0) return
      call h5dget_type_f(dset, dtype, error)
      type_class = -1
      if (error == 0) call h5tget_class_f(dtype, type_class, error)
      if (error == 0) call h5tclose_f(dtype, error)
      if (type_class /= H5T_INTEGER_F .and. type_class /= H5T_FLOAT_F) then
         call h5dclose_f(dset, error)
         dset = -1
         call set_error(status, code, file%path//":"//name//": expected a numeric dataset (integers or floating "// &
            "point), found "//type_name(type_class))
      end if
   end subroutine read_checked

   !> An HDF5 type class in words.
   function type_name(type_class) result(name)
      integer, intent(in) :: type_class
      character(len=:), allocatable :: name
      if (type_class == H5T_STRING_F) then
         name = "strings"
      else if (type_class == H5T_COMPOUND_F) then
         name = "a compound type (complex numbers or records)"
      else if (type_class == H5T_ENUM_F) then
         name = "an enumeration (booleans)"
      else
         name = "a type of class "//char(48 + max(0, min(type_class, 9)))
      end if
   end function type_name

   !> Close a dataset after reading; an error of the read or of the close is reported.
   subroutine finish_read(file, name, dset, read_error, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer(hid_t), intent(inout) :: dset
      integer, intent(in) :: read_error, code
      type(status_type), intent(inout) :: status
      integer :: close_error
      call h5dclose_f(dset, close_error)
      if (read_error /= 0 .or. close_error /= 0) call set_error(status, code, file%path//":"//name// &
         ": cannot read the dataset")
   end subroutine finish_read

   !> The dataset `name`, checked to be of rank `rank`, read as HDF5 type `dtype` into the
   !> contiguous memory at `buffer`; with no buffer (c_null_ptr), only its dims (Fortran
   !> order) are returned, to size the buffer of a second call.
   subroutine read_plain(file, name, rank, dtype, buffer, fdims, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer, intent(in) :: rank, code
      integer(hid_t), intent(in) :: dtype
      type(c_ptr), intent(in) :: buffer
      integer(hsize_t), intent(out) :: fdims(7)
      type(status_type), intent(inout) :: status
      integer(hid_t) :: dset
      type(c_ptr) :: into
      integer :: error
      fdims = 0
      if (status%code /= 0) return
      call read_checked(file, name, rank, dset, fdims, status, code)
      if (status%code /= 0) return
      error = 0
      into = buffer
      if (c_associated(into)) call h5dread_f(dset, dtype, into, error)
      call finish_read(file, name, dset, error, status, code)
   end subroutine read_plain

   subroutine read_real0(file, name, value, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      real(dp), intent(out), target :: value
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer(hsize_t) :: fdims(7)
      value = 0
      call read_plain(file, name, 0, H5T_NATIVE_DOUBLE, c_loc(value), fdims, status, code)
   end subroutine read_real0

   subroutine read_int0(file, name, value, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer, intent(out), target :: value
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer(hsize_t) :: fdims(7)
      value = 0
      call read_plain(file, name, 0, H5T_NATIVE_INTEGER, c_loc(value), fdims, status, code)
   end subroutine read_int0

   subroutine read_real1(file, name, values, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      real(dp), allocatable, target, intent(out) :: values(:)
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer(hsize_t) :: fdims(7)
      call read_plain(file, name, 1, H5T_NATIVE_DOUBLE, c_null_ptr, fdims, status, code)
      allocate(values(fdims(1)))
      if (size(values) > 0) call read_plain(file, name, 1, H5T_NATIVE_DOUBLE, c_loc(values), fdims, status, code)
   end subroutine read_real1

   subroutine read_int1(file, name, values, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      integer, allocatable, target, intent(out) :: values(:)
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer(hsize_t) :: fdims(7)
      call read_plain(file, name, 1, H5T_NATIVE_INTEGER, c_null_ptr, fdims, status, code)
      allocate(values(fdims(1)))
      if (size(values) > 0) call read_plain(file, name, 1, H5T_NATIVE_INTEGER, c_loc(values), fdims, status, code)
   end subroutine read_int1

   !> A 2-D dataset as map(i, j) with i the C-order first index (the row).
   subroutine read_real2(file, name, map, status, code)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: name
      real(dp), allocatable, intent(out) :: map(:, :)
      type(status_type), intent(inout) :: status
      integer, intent(in) :: code
      integer(hid_t) :: dset
      integer(hsize_t) :: fdims(7)
      real(dp), allocatable :: stored(:, :)
      integer :: error
      allocate(map(0, 0))
      if (status%code /= 0) return
      call read_checked(file, name, 2, dset, fdims, status, code)
      if (status%code /= 0) return
      allocate(stored(fdims(1), fdims(2)))
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, stored, fdims(1:2), error)
      call finish_read(file, name, dset, error, status, code)
      if (status%code /= 0) return
      deallocate(map)
      allocate(map(fdims(2), fdims(1)))
      call transpose_into(stored, map)
   end subroutine read_real2

   !> out = transpose(a), by tiles of 32 x 32 on all threads. The intrinsic writes one
   !> column's worth apart at every step: 0.20 s for a 4096^2 map against 0.07 s in tiles
   !> (each map written or read goes through here: HDF5 stores rows first).
   subroutine transpose_into(a, out)
      real(dp), intent(in) :: a(:, :)
      real(dp), intent(out) :: out(:, :)
      integer, parameter :: tile = 32
      integer :: i, j, i0, j0
      !$omp parallel do private(i, j, i0) schedule(static)
      do j0 = 1, size(a, 2), tile
         do i0 = 1, size(a, 1), tile
            do j = j0, min(j0 + tile - 1, size(a, 2))
               do i = i0, min(i0 + tile - 1, size(a, 1))
                  out(j, i) = a(i, j)
               end do
            end do
         end do
      end do
   end subroutine transpose_into
   !> The C string at `pointer`, at most `length` characters.
   function c_text(pointer, length) result(text)
      type(c_ptr), intent(in) :: pointer
      integer, intent(in) :: length
      character(len=:), allocatable :: text
      character(kind=c_char), pointer :: chars(:)
      integer :: k
      call c_f_pointer(pointer, chars, [length + 1])
      do k = 1, length + 1
         if (chars(k) == c_null_char) exit
      end do
      allocate(character(len=k - 1) :: text)
      text = transfer(chars(1:k - 1), text)
   end function c_text
end module femcod_hdf5
