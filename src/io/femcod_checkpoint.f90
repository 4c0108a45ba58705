!> Checkpoint files (PREFIX.ckpt.h5): written atomically (temporary name, then rename),
!> so a run killed at any moment leaves either the previous checkpoint or the new one,
!> never a partial file. A checkpoint holds the whole problem and the options that
!> shape the history, and is refused for any other; then the solver's state, stored
!> field by field as the state's `visit` lists them (core/femcod_state_visitor): the
!> writer and the reader here know no field of any state.
!>
!> Layout: /deck (label, NP, pixel, MAXCONT, young, poisson; lower, upper),
!> /options (attribute `history`: every option that shapes the history, one text,
!> solvers' history_options), then one group
!> per group the state visits (for the incremental solver /state, /history,
!> /states/<k>, /counters), a dataset per field with its name.
module femcod_checkpoint
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_IO
   use femcod_problem, only: contact_problem
   use femcod_strings, only: int_str, format_real
   use femcod_files, only: atomic_rename, remove_file, temporary_name
   use femcod_solver_options, only: contact_options, history_options, first_difference
   use femcod_state_visitor, only: state_visitor, visitable
   use femcod_hdf5, only: h5_file, h5_create, h5_open, h5_close, h5_group, h5_write, h5_read, h5_attribute, &
      h5_read_string_attribute, h5_exists
   use femcod_about, only: FEMCOD_VERSION
   implicit none
   private
   public :: write_checkpoint, read_checkpoint

   !> Marks a file as a femcod checkpoint (attribute /format).
   character(len=*), parameter :: FORMAT_TAG = "femcod checkpoint 5"

   !> Stores each visited field as a dataset of an open HDF5 file.
   type, extends(state_visitor) :: h5_writer
      type(h5_file) :: file
      character(len=:), allocatable :: where
   contains
      procedure :: group => writer_group
      procedure :: integer_value => write_integer
      procedure :: long_value => write_long
      procedure :: real_value => write_real
      procedure :: logical_value => write_logical
      procedure :: integer_array => write_integers
      procedure :: real_array => write_reals
      procedure :: integer_prefix => write_integer_prefix
      procedure :: real_prefix => write_real_prefix
      procedure :: real_rows => write_real_rows
      procedure :: real_triangle => write_real_triangle
   end type h5_writer

   !> Reads each visited field back from the dataset of its name; every shape is checked
   !> against the state's storage (a mismatch is a corrupted checkpoint).
   type, extends(state_visitor) :: h5_reader
      type(h5_file) :: file
      character(len=:), allocatable :: where
   contains
      procedure :: group => reader_group
      procedure :: integer_value => read_integer
      procedure :: long_value => read_long
      procedure :: real_value => read_real
      procedure :: logical_value => read_logical
      procedure :: integer_array => read_integers
      procedure :: real_array => read_reals
      procedure :: integer_prefix => read_integer_prefix
      procedure :: real_prefix => read_real_prefix
      procedure :: real_rows => read_real_rows
      procedure :: real_triangle => read_real_triangle
   end type h5_reader

contains

   !> Store `state` for `problem` and `options` in `path`, atomically.
   subroutine write_checkpoint(path, deck, options, state, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(in) :: deck
      type(contact_options), intent(in) :: options
      class(visitable), intent(inout) :: state
      type(status_type), intent(inout) :: status
      type(h5_writer) :: writer
      character(len=:), allocatable :: tmp
      if (status%code /= 0) return
      tmp = temporary_name(path)
      associate(file => writer%file)
         call h5_create(tmp, file, status)
         file%path = path
         call h5_attribute(file, "/", "format", FORMAT_TAG, status)
         call h5_attribute(file, "/", "femcod_version", FEMCOD_VERSION, status)
         call h5_group(file, "/deck", status)
         call h5_attribute(file, "/deck", "label", deck%label, status)
         call h5_write(file, "/deck/NP", deck%np, "1", status)
         call h5_write(file, "/deck/pixel", deck%pixel, "nm", status)
         call h5_write(file, "/deck/MAXCONT", deck%maxcont, "1", status)
         call h5_write(file, "/deck/young", deck%young, "GPa", status)
         call h5_write(file, "/deck/poisson", deck%poisson, "1", status)
         call h5_write(file, "/deck/lower", deck%lower, "nm", status)
         call h5_write(file, "/deck/upper", deck%upper, "nm", status)
         call h5_group(file, "/options", status)
         ! The whole option set that shapes the history, as one text (history_options):
         ! --restart compares it whole, so no checkpoint continues as another physics.
         call h5_attribute(file, "/options", "history", history_options(options), status)
         if (status%code == 0) then
            call state%visit(writer)
            if (writer%status%code /= 0) call set_error(status, writer%status%code, writer%status%message)
         end if
         call h5_close(file, status)
      end associate
      if (status%code /= 0) then
         call remove_file(tmp)
         return
      end if
      call atomic_rename(tmp, path, status)
   end subroutine write_checkpoint

   !> Read the state stored in `path` into `state`, which the caller has set up for this
   !> problem and these options (the reader fills the stored fields; derived ones are the
   !> caller's to rebuild). Refused (STATUS_BAD_INPUT) unless the checkpoint was written
   !> for exactly this problem and these options.
   subroutine read_checkpoint(path, deck, options, state, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(in) :: deck
      type(contact_options), intent(in) :: options
      class(visitable), intent(inout) :: state
      type(status_type), intent(inout) :: status
      type(h5_reader) :: reader
      character(len=:), allocatable :: tag, label, stored
      real(dp), allocatable :: r1(:), r2(:, :)
      real(dp) :: r
      integer :: i
      integer, parameter :: bad = STATUS_BAD_INPUT
      if (status%code /= 0) return
      associate(file => reader%file)
      call h5_open(path, file, status, bad)
      call h5_read_string_attribute(file, "/", "format", len(FORMAT_TAG), tag, status, bad)
      if (status%code /= 0) then
         call h5_close(file, status)
         status%message = path//": not a femcod checkpoint (truncated or corrupted; delete it: femcod replaces "// &
            "only files it can read as its own)"
         return
      end if
      if (tag /= FORMAT_TAG) then
         call refuse("not a femcod checkpoint of this version (format '"//tag//"')")
         return
      end if
      ! The deck: everything must match exactly.
      ! Read the stored label whole, whatever its length, so that a refusal quotes it.
      call h5_read_string_attribute(file, "/deck", "label", max(len(deck%label) + 1, 65536), label, status, bad)
      call h5_read(file, "/deck/NP", i, status, bad)
      if (status%code /= 0) return
      if (i /= deck%np) then
         call refuse("written for a deck with NP = "//int_str(i)//", this deck has NP = "//int_str(deck%np))
         return
      end if
      if (label /= deck%label) then
         call refuse("written for the deck '"//label//"', not '"//deck%label//"'")
         return
      end if
      call h5_read(file, "/deck/pixel", r, status, bad)
      if (status%code == 0 .and. r /= deck%pixel) then
         call refuse("pixel size "//format_real(r)//" nm differs from the deck's "//format_real(deck%pixel))
         return
      end if
      call h5_read(file, "/deck/MAXCONT", i, status, bad)
      if (status%code == 0 .and. i /= deck%maxcont) then
         call refuse("MAXCONT "//int_str(i)//" differs from the deck's "//int_str(deck%maxcont))
         return
      end if
      call h5_read(file, "/deck/young", r1, status, bad)
      if (status%code == 0 .and. .not. same(r1, deck%young)) then
         call refuse("Young's moduli differ from the deck's")
         return
      end if
      call h5_read(file, "/deck/poisson", r1, status, bad)
      if (status%code == 0 .and. .not. same(r1, deck%poisson)) then
         call refuse("Poisson's ratios differ from the deck's")
         return
      end if
      call h5_read(file, "/deck/lower", r2, status, bad)
      if (status%code == 0 .and. .not. same2(r2, deck%lower)) then
         call refuse("the lower surface's heights differ from the deck's")
         return
      end if
      call h5_read(file, "/deck/upper", r2, status, bad)
      if (status%code == 0 .and. .not. same2(r2, deck%upper)) then
         call refuse("the upper surface's heights differ from the deck's")
         return
      end if
      ! The options that shape the history, compared whole (history_options).
      if (status%code == 0) then
         if (.not. h5_exists(file, "/options")) then
            call refuse("written by an earlier femcod that did not store its whole option set")
            return
         end if
         call h5_read_string_attribute(file, "/options", "history", 65536, stored, status, bad)
         if (status%code /= 0) then
            status = status_type()
            call refuse("written by an earlier femcod that did not store its whole option set")
            return
         end if
         if (stored /= history_options(options)) then
            call refuse("written with other options: "//first_difference(stored, history_options(options)))
            return
         end if
      end if
      if (status%code /= 0) then
         call h5_close(file, status)
         return
      end if
      ! The state, field by field.
      call state%visit(reader)
      if (reader%status%code /= 0) then
         call refuse(reader%status%message)
         return
      end if
      call h5_close(file, status)
      end associate
   contains
      subroutine refuse(why)
         character(len=*), intent(in) :: why
         type(status_type) :: ignore
         call h5_close(reader%file, ignore)
         call set_error(status, bad, path//": checkpoint refused: "//why// &
            " (start afresh with --force, which replaces it)")
      end subroutine refuse
      pure logical function same(a, b)
         real(dp), intent(in) :: a(:), b(:)
         same = size(a) == size(b)
         if (same) same = all(a == b)
      end function same
      pure logical function same2(a, b)
         real(dp), intent(in) :: a(:, :), b(:, :)
         same2 = all(shape(a) == shape(b))
         if (same2) same2 = all(a == b)
      end function same2
   end subroutine read_checkpoint

   ! ---- the writer ---------------------------------------------------------------

   !> Datasets of the sub-object `name` go to the group /name (created with its parents).
   subroutine writer_group(self, name)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer :: k
      self%where = "/"//name
      do k = 2, len(self%where)
         if (self%where(k:k) == "/") call make(self%where(1:k - 1))
      end do
      call make(self%where)
   contains
      subroutine make(group)
         character(len=*), intent(in) :: group
         if (.not. h5_exists(self%file, group)) call h5_group(self%file, group, self%status)
      end subroutine make
   end subroutine writer_group

   subroutine write_integer(self, name, value)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout) :: value
      call h5_write(self%file, self%where//"/"//name, value, "1", self%status)
   end subroutine write_integer

   !> 64-bit counters as doubles (exact below 2**53).
   subroutine write_long(self, name, value)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(inout) :: value
      call h5_write(self%file, self%where//"/"//name, real(value, dp), "1", self%status)
   end subroutine write_long

   subroutine write_real(self, name, value)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: value
      call h5_write(self%file, self%where//"/"//name, value, "", self%status)
   end subroutine write_real

   subroutine write_logical(self, name, value)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      logical, intent(inout) :: value
      call h5_write(self%file, self%where//"/"//name, merge(1, 0, value), "1", self%status)
   end subroutine write_logical

   subroutine write_integers(self, name, values)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, allocatable, intent(inout) :: values(:)
      call h5_write(self%file, self%where//"/"//name, values, "1", self%status)
   end subroutine write_integers

   subroutine write_reals(self, name, values)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), allocatable, intent(inout) :: values(:)
      call h5_write(self%file, self%where//"/"//name, values, "", self%status)
   end subroutine write_reals

   subroutine write_integer_prefix(self, name, values, n)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout) :: values(:)
      integer, intent(in) :: n
      call h5_write(self%file, self%where//"/"//name, values(1:n), "1", self%status)
   end subroutine write_integer_prefix

   subroutine write_real_prefix(self, name, values, n)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: values(:)
      integer, intent(in) :: n
      call h5_write(self%file, self%where//"/"//name, values(1:n), "", self%status)
   end subroutine write_real_prefix

   subroutine write_real_rows(self, name, values, n)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: values(:, :)
      integer, intent(in) :: n
      call h5_write(self%file, self%where//"/"//name, values(1:n, :), "", self%status)
   end subroutine write_real_rows

   !> The upper triangle of values(1:n, 1:n), packed column by column.
   subroutine write_real_triangle(self, name, values, n)
      class(h5_writer), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: values(:, :)
      integer, intent(in) :: n
      real(dp), allocatable :: packed(:)
      integer :: j, at
      allocate(packed(int(n, i8)*(n + 1)/2))
      at = 0
      do j = 1, n
         packed(at + 1:at + j) = values(1:j, j)
         at = at + j
      end do
      call h5_write(self%file, self%where//"/"//name, packed, "", self%status)
   end subroutine write_real_triangle

   ! ---- the reader ---------------------------------------------------------------

   subroutine reader_group(self, name)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      self%where = "/"//name
   end subroutine reader_group

   subroutine read_integer(self, name, value)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout) :: value
      call h5_read(self%file, self%where//"/"//name, value, self%status, STATUS_BAD_INPUT)
   end subroutine read_integer

   subroutine read_long(self, name, value)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(inout) :: value
      real(dp) :: r
      call h5_read(self%file, self%where//"/"//name, r, self%status, STATUS_BAD_INPUT)
      if (self%status%code == 0) value = nint(r, i8)
   end subroutine read_long

   subroutine read_real(self, name, value)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: value
      call h5_read(self%file, self%where//"/"//name, value, self%status, STATUS_BAD_INPUT)
   end subroutine read_real

   subroutine read_logical(self, name, value)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      logical, intent(inout) :: value
      integer :: i
      call h5_read(self%file, self%where//"/"//name, i, self%status, STATUS_BAD_INPUT)
      if (self%status%code == 0) value = i == 1
   end subroutine read_logical

   subroutine read_integers(self, name, values)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, allocatable, intent(inout) :: values(:)
      call h5_read(self%file, self%where//"/"//name, values, self%status, STATUS_BAD_INPUT)
   end subroutine read_integers

   subroutine read_reals(self, name, values)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), allocatable, intent(inout) :: values(:)
      call h5_read(self%file, self%where//"/"//name, values, self%status, STATUS_BAD_INPUT)
   end subroutine read_reals

   subroutine read_integer_prefix(self, name, values, n)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout) :: values(:)
      integer, intent(in) :: n
      integer, allocatable :: stored(:)
      call h5_read(self%file, self%where//"/"//name, stored, self%status, STATUS_BAD_INPUT)
      if (.not. fits(self, name, size(stored), n, size(values))) return
      values(1:n) = stored
   end subroutine read_integer_prefix

   subroutine read_real_prefix(self, name, values, n)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: values(:)
      integer, intent(in) :: n
      real(dp), allocatable :: stored(:)
      call h5_read(self%file, self%where//"/"//name, stored, self%status, STATUS_BAD_INPUT)
      if (.not. fits(self, name, size(stored), n, size(values))) return
      values(1:n) = stored
   end subroutine read_real_prefix

   subroutine read_real_rows(self, name, values, n)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: values(:, :)
      integer, intent(in) :: n
      real(dp), allocatable :: stored(:, :)
      call h5_read(self%file, self%where//"/"//name, stored, self%status, STATUS_BAD_INPUT)
      if (self%status%code /= 0) return
      if (size(stored, 2) /= size(values, 2)) then
         call set_error(self%status, STATUS_BAD_INPUT, self%where//"/"//name//": "//int_str(size(stored, 2))// &
            " columns stored, "//int_str(size(values, 2))//" expected (corrupted)")
         return
      end if
      if (.not. fits(self, name, size(stored, 1), n, size(values, 1))) return
      values(1:n, :) = stored
   end subroutine read_real_rows

   subroutine read_real_triangle(self, name, values, n)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: values(:, :)
      integer, intent(in) :: n
      real(dp), allocatable :: packed(:)
      integer :: j, at
      call h5_read(self%file, self%where//"/"//name, packed, self%status, STATUS_BAD_INPUT)
      if (self%status%code /= 0) return
      if (n < 0 .or. n > min(size(values, 1), size(values, 2)) .or. size(packed, kind=i8) /= int(n, i8)*(n + 1)/2) then
         call set_error(self%status, STATUS_BAD_INPUT, self%where//"/"//name//": not the triangle of "// &
            int_str(n)//" columns (corrupted)")
         return
      end if
      at = 0
      do j = 1, n
         values(1:j, j) = packed(at + 1:at + j)
         at = at + j
      end do
   end subroutine read_real_triangle

   !> Whether `stored` entries are the n the state expects, within its storage of
   !> `room`; an error naming the field otherwise.
   logical function fits(self, name, stored, n, room)
      class(h5_reader), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer, intent(in) :: stored, n, room
      fits = .false.
      if (self%status%code /= 0) return
      if (n < 0 .or. n > room .or. stored /= n) then
         call set_error(self%status, STATUS_BAD_INPUT, self%where//"/"//name//": "//int_str(stored)// &
            " entries stored, "//int_str(n)//" expected (corrupted)")
         return
      end if
      fits = .true.
   end function fits

end module femcod_checkpoint
