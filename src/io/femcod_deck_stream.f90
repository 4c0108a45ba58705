!> A text deck read in slabs: its header as read_deck reads it (femcod_deck's
!> read_deck_header), then its 2 NP^2 heights in file order, as many at a time as the
!> caller asks for, through a buffer of CHUNK_BYTES: the file is never held whole, so a
!> deck larger than the 2 GiB that read_file takes (8192^2 and up) is read too. A stream
!> may also cover one range of the file's bytes (open_deck_range, with count_deck_range
!> and separator_at_or_after to cut and count the ranges): femcod-mpi's ranks each read
!> their own range this way (mpi/src/femcod_mpi_input).
!>
!> Every message is read_deck's: the file, the line, what was expected and what was
!> found (a value that is not a finite number, or beyond 1e12 nm, with its row and
!> column; too few or too many heights; a binary control character).
module femcod_deck_stream
   use femcod_kinds, only: dp, i8
   use femcod_problem, only: contact_problem, MAX_HEIGHT
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_IO
   use femcod_deck, only: read_deck_header
   use femcod_bytes, only: words_little_endian, first_control_byte, scan_tokens
   use femcod_strings, only: int_str, parse_real
   use femcod_files, only: path_exists, path_is_directory, os_error_text, clear_write_error
   implicit none
   private
   public :: deck_stream, open_deck_stream, read_deck_heights, close_deck_stream, read_text_deck_header, CHUNK_BYTES
   public :: open_deck_range, count_deck_range, separator_at_or_after, too_few_heights, binary_byte, balanced_cuts

   !> Bytes read from the file at a time (the buffer holds one chunk and the part of a
   !> token cut at its end).
   integer, parameter :: CHUNK_BYTES = 4*1024*1024
   !> The header (lines 1 to 5) is looked for in the file's first bytes.
   integer, parameter :: HEADER_BYTES = 1024*1024

   !> An open text deck, positioned at its next height.
   type :: deck_stream
      character(len=:), allocatable :: path
      integer :: unit = -1
      !> The file's size and the next byte to read (1-based).
      integer(i8) :: size = 0, next = 1
      !> NP, and the heights handed out so far (of 2 NP^2).
      integer :: np = 0
      integer(i8) :: delivered = 0
      !> The current chunk: its text, its tokens' bounds and lines, the values they read
      !> as (huge where a token is not a height), and how many were handed out.
      character(len=:), allocatable :: text, carry
      integer, allocatable :: first(:), last(:), line(:)
      real(dp), allocatable :: value(:)
      integer :: ntok = 0, used = 0
      !> The chunk's first token that is not a height (huge: none).
      integer :: first_bad = huge(0)
      !> The line at the start of the next chunk; the last line that holds anything.
      integer :: line0 = 1, last_line = 1
      !> The file's byte at text(1:1).
      integer(i8) :: text_start = 1
      !> Bytes read at a time (CHUNK_BYTES unless the caller chose).
      integer :: chunk = CHUNK_BYTES
      logical :: at_end = .false.
   end type deck_stream

contains

   !> Open the text deck `path` and read its header into `deck` (no heights); the
   !> stream then stands at the first height. `chunk_bytes`: read that many bytes at a
   !> time (CHUNK_BYTES by default; the tests take a few, to cut tokens and lines).
   subroutine open_deck_stream(path, stream, deck, status, chunk_bytes)
      character(len=*), intent(in) :: path
      type(deck_stream), intent(out) :: stream
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      integer, intent(in), optional :: chunk_bytes
      character(len=:), allocatable :: head
      integer :: ios, k, at, header_end
      stream%path = path
      if (present(chunk_bytes)) stream%chunk = max(1, chunk_bytes)
      ! read_file's messages (femcod_files) for what is not a readable file.
      if (path_is_directory(path)) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a deck file, found a directory")
         return
      end if
      if (.not. path_exists(path)) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a deck file, found no such file")
         return
      end if
      call clear_write_error()
      open(newunit=stream%unit, file=path, access="stream", form="unformatted", action="read", status="old", &
         iostat=ios)
      if (ios /= 0) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a deck file, cannot open it ("// &
            os_error_text()//")")
         stream%unit = -1
         return
      end if
      inquire(unit=stream%unit, size=stream%size)
      if (stream%size <= 0) then
         call set_error(status, STATUS_BAD_INPUT, path//":1: expected a label line, found an empty file")
         call close_deck_stream(stream)
         return
      end if
      allocate(character(len=int(min(stream%size, int(HEADER_BYTES, i8)))) :: head)
      read(stream%unit, pos=1, iostat=ios) head
      if (ios /= 0) then
         call set_error(status, STATUS_IO, path//": cannot read it")
         call close_deck_stream(stream)
         return
      end if
      ! Lines 1 to 5 with their line ends; the heights start after the fifth.
      header_end = len(head)
      at = 0
      do k = 1, 5
         ios = index(head(at + 1:), new_line("a"))
         if (ios == 0) exit
         at = at + ios
         if (k == 5) header_end = at
      end do
      call read_deck_header(path, head(1:header_end), deck, status)
      if (status%code /= 0) then
         call close_deck_stream(stream)
         return
      end if
      stream%np = deck%np
      stream%next = header_end + 1
      stream%line0 = 1 + count_line_ends(head(1:header_end))
      stream%last_line = last_line_of(head(1:header_end), stream%line0)
      stream%carry = ""
      stream%text = ""
      stream%at_end = stream%next > stream%size
   end subroutine open_deck_stream

   !> The next size(values) heights (nm) in file order: the lower surface's NP^2 row by
   !> row, then the upper's. After the last of the 2 NP^2, the rest of the file must be
   !> blank (else: "expected the end of the deck ...").
   subroutine read_deck_heights(stream, values, status)
      type(deck_stream), intent(inout) :: stream
      real(dp), intent(out) :: values(:)
      type(status_type), intent(inout) :: status
      integer(i8) :: total
      integer :: filled, take, k
      total = 2*int(stream%np, i8)**2
      filled = 0
      do while (filled < size(values))
         if (stream%used == stream%ntok) then
            call next_chunk(stream, status)
            if (status%code /= 0) return
            if (stream%ntok == 0) then
               call set_error(status, STATUS_BAD_INPUT, too_few_heights(stream%path, stream%last_line, stream%np, &
                  stream%delivered))
               return
            end if
         end if
         take = min(size(values) - filled, stream%ntok - stream%used)
         if (stream%first_bad <= stream%used + take) then
            k = stream%first_bad - stream%used
            call refuse_height(stream, stream%first_bad, stream%delivered + k, status)
            return
         end if
         values(filled + 1:filled + take) = stream%value(stream%used + 1:stream%used + take)
         filled = filled + take
         stream%used = stream%used + take
         stream%delivered = stream%delivered + take
      end do
      if (stream%delivered == total) call expect_end(stream, status)
   end subroutine read_deck_heights

   !> read_deck's message for a deck whose heights end early: `found` of the 2 NP^2, the
   !> file's last line that holds anything at `line`.
   function too_few_heights(path, line, np, found) result(message)
      character(len=*), intent(in) :: path
      integer, intent(in) :: line, np
      integer(i8), intent(in) :: found
      character(len=:), allocatable :: message
      message = path//":"//int_str(line)//": expected "//int_str(2*int(np, i8)**2)//" heights (NP**2 = "// &
         int_str(int(np, i8)**2)//" lower, then as many upper), found "//int_str(found)//" before the end of the file"
   end function too_few_heights

   !> A stream over bytes first_byte .. last_byte of the text deck `path` (NP `np`), whose
   !> header was read elsewhere: femcod-mpi's ranks each read their own range of the
   !> heights, which starts after a separator and ends before one (or at the end of the
   !> file). `line` is the file's line at first_byte and `before` the heights before it,
   !> so that read_deck_heights gives read_deck's messages (line, row and column as in the
   !> whole file) and, once the 2 NP^2 are given, checks that the range holds no more.
   subroutine open_deck_range(path, np, first_byte, last_byte, line, before, stream, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: np, line
      integer(i8), intent(in) :: first_byte, last_byte, before
      type(deck_stream), intent(out) :: stream
      type(status_type), intent(inout) :: status
      stream%path = path
      call open_bytes(path, stream%unit, status)
      if (status%code /= 0) return
      stream%np = np
      stream%size = last_byte
      stream%next = first_byte
      stream%line0 = line
      stream%last_line = line
      stream%delivered = before
      stream%carry = ""
      stream%text = ""
      stream%at_end = stream%next > stream%size
   end subroutine open_deck_range

   !> read_deck's message for a binary byte of code `code` at byte `at`, on line `line`.
   function binary_byte(path, line, code, at) result(message)
      character(len=*), intent(in) :: path
      integer, intent(in) :: line, code
      integer(i8), intent(in) :: at
      character(len=:), allocatable :: message
      message = path//":"//int_str(line)//": expected a text deck, found a binary control character (code "// &
         int_str(code)//") at byte "//int_str(at)
   end function binary_byte

   !> Consecutive blocks of work `weights` (in file order) cut into `parts` runs of about
   !> equal weight: part r (1-based) takes blocks cuts(r - 1) + 1 .. cuts(r), each block
   !> going to the part in whose share the middle of its weight falls (cuts(0) = 0,
   !> cuts(parts) = the blocks; a part may take none).
   pure function balanced_cuts(weights, parts) result(cuts)
      real(dp), intent(in) :: weights(:)
      integer, intent(in) :: parts
      integer :: cuts(0:parts)
      real(dp) :: total, before
      integer :: k, r
      total = sum(weights)
      cuts = 0
      before = 0
      do k = 1, size(weights)
         r = 1
         if (total > 0) r = min(parts, 1 + int((before + weights(k)/2)*parts/total))
         cuts(r:) = k
         before = before + weights(k)
      end do
      cuts(parts) = size(weights)
   end function balanced_cuts

   !> Whether a byte separates heights (a blank, a control character or a comma).
   elemental logical function separates(byte)
      character(len=1), intent(in) :: byte
      separates = iachar(byte) < 33 .or. byte == ","
   end function separates

   !> `path` opened for reading its bytes (unit -1 and STATUS_IO if it cannot be).
   subroutine open_bytes(path, unit, status)
      character(len=*), intent(in) :: path
      integer, intent(out) :: unit
      type(status_type), intent(inout) :: status
      integer :: ios
      open(newunit=unit, file=path, access="stream", form="unformatted", action="read", status="old", iostat=ios)
      if (ios /= 0) then
         call set_error(status, STATUS_IO, path//": cannot open it ("//os_error_text()//")")
         unit = -1
      end if
   end subroutine open_bytes

   !> The tokens (heights or not) and the line ends in bytes first_byte .. last_byte of
   !> `path` (a range as open_deck_range takes it), read a chunk at a time; `binary`:
   !> the first binary control byte's place in the file (0: none), the line ends before
   !> it in the range, and its code. `at_a_time`: read that many bytes at a time
   !> (CHUNK_BYTES by default; the tests take a few, to cut tokens and lines).
   subroutine count_deck_range(path, first_byte, last_byte, tokens, line_ends, binary, status, at_a_time)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: first_byte, last_byte
      integer(i8), intent(out) :: tokens, line_ends, binary(3)
      type(status_type), intent(inout) :: status
      integer, intent(in), optional :: at_a_time
      character(len=:), allocatable :: text
      integer(i8) :: at
      integer :: unit, ios, n, count, ends, bad, chunk
      logical :: inside
      tokens = 0
      line_ends = 0
      binary = 0
      inside = .false.
      chunk = CHUNK_BYTES
      if (present(at_a_time)) chunk = max(1, at_a_time)
      if (last_byte < first_byte) return
      call open_bytes(path, unit, status)
      if (status%code /= 0) return
      at = first_byte
      do while (at <= last_byte)
         n = int(min(int(chunk, i8), last_byte - at + 1))
         if (allocated(text)) deallocate(text)
         allocate(character(len=n) :: text)
         read(unit, pos=at, iostat=ios) text
         if (ios /= 0) then
            call set_error(status, STATUS_IO, path//": cannot read it past byte "//int_str(at))
            exit
         end if
         if (binary(1) == 0) then
            bad = first_control(text)
            if (bad > 0) binary = [at + bad - 1, line_ends + count_line_ends(text(1:bad - 1)), &
               int(iachar(text(bad:bad)), i8)]
         end if
         call scan_all(text, 0, 0, count, ends)
         ! A token cut by the chunk's end was counted with the chunk before.
         if (inside .and. .not. separates(text(1:1))) count = count - 1
         inside = .not. separates(text(n:n))
         tokens = tokens + count
         line_ends = line_ends + ends
         at = at + n
      end do
      close(unit)
   end subroutine count_deck_range

   !> The first byte at or after `from` of `path` (of `size` bytes) that separates heights
   !> (a blank, a control character or a comma); size + 1 if there is none.
   subroutine separator_at_or_after(path, from, size, at, status)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: from, size
      integer(i8), intent(out) :: at
      type(status_type), intent(inout) :: status
      character(len=4096) :: window
      integer :: unit, ios, n, k
      at = size + 1
      if (from > size) return
      call open_bytes(path, unit, status)
      if (status%code /= 0) return
      at = from
      do while (at <= size)
         n = int(min(int(len(window), i8), size - at + 1))
         read(unit, pos=at, iostat=ios) window(1:n)
         if (ios /= 0) then
            call set_error(status, STATUS_IO, path//": cannot read it past byte "//int_str(at))
            exit
         end if
         do k = 1, n
            if (separates(window(k:k))) then
               at = at + k - 1
               close(unit)
               return
            end if
         end do
         at = at + n
      end do
      close(unit)
   end subroutine separator_at_or_after

   !> A text deck's header (label, NP, pixel, MAXCONT, materials; no heights), with
   !> read_deck's checks and messages: only its first lines are read.
   subroutine read_text_deck_header(path, deck, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(deck_stream) :: stream
      call open_deck_stream(path, stream, deck, status)
      call close_deck_stream(stream)
   end subroutine read_text_deck_header

   !> The file closed (it may be closed twice).
   subroutine close_deck_stream(stream)
      type(deck_stream), intent(inout) :: stream
      if (stream%unit /= -1) close(stream%unit)
      stream%unit = -1
   end subroutine close_deck_stream

   !> The next chunk of the file that holds a token (ntok = 0: the end of the file).
   subroutine next_chunk(stream, status)
      type(deck_stream), intent(inout) :: stream
      type(status_type), intent(inout) :: status
      do
         call load_chunk(stream, status)
         if (status%code /= 0 .or. stream%ntok > 0) return
         if (stream%at_end .and. len(stream%carry) == 0) return
      end do
   end subroutine next_chunk

   !> The next chunk of the file: cut after its last separator (the rest carried to the
   !> next one), refused if it holds a control byte, tokenized with the lines of its
   !> tokens, and each token read as a height, on all threads.
   subroutine load_chunk(stream, status)
      type(deck_stream), intent(inout) :: stream
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: bytes
      integer :: n, ios, cut, bad, count, ends, k
      stream%ntok = 0
      stream%first_bad = huge(0)
      stream%used = 0
      if (stream%at_end .and. len(stream%carry) == 0) return
      n = int(min(int(stream%chunk, i8), stream%size - stream%next + 1))
      allocate(character(len=max(n, 0)) :: bytes)
      if (n > 0) then
         read(stream%unit, pos=stream%next, iostat=ios) bytes
         if (ios /= 0) then
            call set_error(status, STATUS_IO, stream%path//": cannot read it past byte "//int_str(stream%next))
            return
         end if
         stream%next = stream%next + n
      end if
      stream%at_end = stream%next > stream%size
      stream%text_start = stream%next - n - len(stream%carry)
      stream%text = stream%carry//bytes
      deallocate(bytes)
      cut = len(stream%text)
      if (.not. stream%at_end) then
         do while (cut > 0)
            if (iachar(stream%text(cut:cut)) < 33 .or. stream%text(cut:cut) == ",") exit
            cut = cut - 1
         end do
      end if
      stream%carry = stream%text(cut + 1:)
      stream%text = stream%text(1:cut)
      bad = first_control(stream%text)
      if (bad > 0) then
         call set_error(status, STATUS_BAD_INPUT, binary_byte(stream%path, stream%line0 + &
            count_line_ends(stream%text(1:bad - 1)), iachar(stream%text(bad:bad)), stream%text_start + bad - 1))
         return
      end if
      call scan_all(stream%text, 0, stream%line0, count, ends)
      if (allocated(stream%first)) deallocate(stream%first, stream%last, stream%line, stream%value)
      allocate(stream%first(count), stream%last(count), stream%line(count), stream%value(count))
      call scan_all(stream%text, 0, stream%line0, count, ends, stream%first, stream%last, stream%line)
      stream%line0 = stream%line0 + ends
      if (len(stream%text) > 0) stream%last_line = last_line_of(stream%text, stream%line0)
      stream%ntok = count
      bad = huge(0)
      !$omp parallel do schedule(static) reduction(min: bad)
      do k = 1, count
         call read_height(stream%text(stream%first(k):stream%last(k)), stream%value(k))
         if (stream%value(k) == huge(1.0_dp)) bad = min(bad, k)
      end do
      !$omp end parallel do
      stream%first_bad = bad
   end subroutine load_chunk

   !> A token as a height: its value, or huge when it is not a finite number within
   !> MAX_HEIGHT.
   subroutine read_height(token, value)
      character(len=*), intent(in) :: token
      real(dp), intent(out) :: value
      logical :: ok
      call parse_real(token, value, ok)
      if (ok) ok = abs(value) <= MAX_HEIGHT
      if (.not. ok) value = huge(1.0_dp)
   end subroutine read_height

   !> read_deck's message for token k of the chunk, height number m (1-based, in file
   !> order): not a number, or beyond 1e12 nm, with its surface, row and column.
   subroutine refuse_height(stream, k, m, status)
      type(deck_stream), intent(in) :: stream
      integer, intent(in) :: k
      integer(i8), intent(in) :: m
      type(status_type), intent(inout) :: status
      integer(i8) :: per_surface, index
      character(len=:), allocatable :: what, where, token
      real(dp) :: v
      logical :: ok
      per_surface = int(stream%np, i8)**2
      index = m - 1
      what = "a lower-surface height"
      if (index >= per_surface) then
         index = index - per_surface
         what = "an upper-surface height"
      end if
      where = "(row "//int_str(index/stream%np + 1)//", column "//int_str(mod(index, int(stream%np, i8)) + 1)//")"
      token = stream%text(stream%first(k):min(stream%last(k), stream%first(k) + 39))
      token = "'"//token//"'"
      if (stream%last(k) - stream%first(k) > 39) token = token//"..."
      call parse_real(stream%text(stream%first(k):stream%last(k)), v, ok)
      if (.not. ok) then
         call set_error(status, STATUS_BAD_INPUT, stream%path//":"//int_str(stream%line(k))//": expected "//what// &
            " in nm "//where//" (a finite number), found "//token)
      else
         call set_error(status, STATUS_BAD_INPUT, stream%path//":"//int_str(stream%line(k))//": expected a height "// &
            "within 1e12 nm "//where//", found "//token)
      end if
   end subroutine refuse_height

   !> After the last height: nothing but separators to the end of the file.
   subroutine expect_end(stream, status)
      type(deck_stream), intent(inout) :: stream
      type(status_type), intent(inout) :: status
      integer :: k
      character(len=:), allocatable :: token
      do while (stream%used == stream%ntok)
         call next_chunk(stream, status)
         if (status%code /= 0) return
         if (stream%ntok == 0) return
      end do
      k = stream%used + 1
      token = "'"//stream%text(stream%first(k):min(stream%last(k), stream%first(k) + 39))//"'"
      if (stream%last(k) - stream%first(k) > 39) token = token//"..."
      call set_error(status, STATUS_BAD_INPUT, stream%path//":"//int_str(stream%line(k))//": expected the end of "// &
         "the deck after the "//int_str(2*int(stream%np, i8)**2)//" heights, found "//token)
   end subroutine expect_end

   !> The tokens of text (separated by blanks, tabs, CR, LF, FF and commas) and its line
   !> ends, counted, and with `first` recorded from token k0 + 1 and line ln0 on.
   subroutine scan_all(text, k0, ln0, count, ends, first, last, line)
      character(len=*), intent(in) :: text
      integer, intent(in) :: k0, ln0
      integer, intent(out) :: count, ends
      integer, intent(inout), optional :: first(:), last(:), line(:)
      integer :: i, k, ln, c
      logical :: inside
      if (words_little_endian()) then
         if (present(first)) then
            call scan_tokens(text, 1, len(text), k0, ln0, count, ends, first, last, line)
         else
            call scan_tokens(text, 1, len(text), k0, ln0, count, ends)
         end if
         return
      end if
      ! Byte by byte where words are not little-endian.
      k = k0
      ln = ln0
      inside = .false.
      do i = 1, len(text)
         c = iachar(text(i:i))
         if (c < 33 .or. c == 44) then
            if (inside .and. present(first)) last(k) = i - 1
            inside = .false.
            if (c == 10) ln = ln + 1
         else if (.not. inside) then
            inside = .true.
            k = k + 1
            if (present(first)) then
               first(k) = i
               line(k) = ln
            end if
         end if
      end do
      if (inside .and. present(first)) last(k) = len(text)
      count = k - k0
      ends = ln - ln0
   end subroutine scan_all

   !> The first byte of text that is a control character but TAB, LF, FF and CR (or
   !> DEL); 0 when there is none.
   integer function first_control(text) result(at)
      character(len=*), intent(in) :: text
      integer :: i, c
      at = 0
      if (words_little_endian()) then
         at = first_control_byte(text)
         if (at == huge(at)) at = 0
         return
      end if
      do i = 1, len(text)
         c = iachar(text(i:i))
         if ((c < 32 .and. c /= 9 .and. c /= 10 .and. c /= 12 .and. c /= 13) .or. c == 127) then
            at = i
            return
         end if
      end do
   end function first_control

   !> The number of the last line of a text that ends on line `line` (one past its
   !> last LF): that line, or the one before when the text ends with its LF.
   pure integer function last_line_of(text, line) result(last)
      character(len=*), intent(in) :: text
      integer, intent(in) :: line
      last = line
      if (len(text) > 0) then
         if (text(len(text):len(text)) == new_line("a")) last = line - 1
      end if
   end function last_line_of

   !> The LF bytes of text.
   pure integer function count_line_ends(text) result(n)
      character(len=*), intent(in) :: text
      integer :: i
      n = 0
      do i = 1, len(text)
         if (text(i:i) == new_line("a")) n = n + 1
      end do
   end function count_line_ends
end module femcod_deck_stream
