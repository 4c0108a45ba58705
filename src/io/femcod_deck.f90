!> The input deck of Appendix B: read, validate and write.
!>
!>     line 1 : label (free text)
!>     line 2 : NP  PIXEL  MAXCONT        integer, real (nm), integer
!>     line 3 : E1  NU1                   lower surface (GPa, -)
!>     line 4 : E2  NU2                   upper surface
!>     line 5 : E3  NU3                   contact / interface elements
!>     then NP*NP lower heights (nm), row by row, then NP*NP upper heights (nm)
!>
!> Lines 2 to 5 hold exactly the values named; the heights are free format from
!> line 6 on (any number per line, separated by blanks, tabs or commas). CRLF line
!> ends and Fortran `D` exponents are accepted. Every error names the file, the line
!> and what was expected and found (doc/deck-format.md). An HDF5 file (by its
!> signature) is read, and a name ending in .h5 written, as the HDF5 deck of the same
!> content (femcod_deck_h5).
module femcod_deck
   use femcod_kinds, only: dp, i8
   use femcod_problem, only: contact_problem, validate_problem, MAX_NP, MIN_PIXEL, MAX_PIXEL, MAX_HEIGHT, &
      MIN_YOUNG, MAX_YOUNG
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_IO, STATUS_USAGE
   use femcod_files, only: write_file, read_file, MAX_TEXT_BYTES
   use femcod_deck_h5, only: read_deck_h5, write_deck_h5, is_hdf5_file
   use femcod_bytes, only: words_little_endian, first_control_byte, scan_tokens, count_tokens
   use femcod_strings, only: count_text, int_str, parse_real, parse_integer, format_real, format_reals, is_digit, text_builder, &
      add_line, add_text, built_text
   !$ use omp_lib, only: omp_get_max_threads
   implicit none
   private
   public :: read_deck, write_deck, read_deck_header


   character(len=*), parameter :: material_names(3) = [character(len=26) :: &
      "lower surface", "upper surface", "contact/interface elements"]

   !> A deck's text and its tokens (first and last character, line), for the messages
   !> `path:line: expected ..., found ...`: per header line 2 to 5 its first token and
   !> count; the first height's token; the last line.
   type :: deck_tokens
      character(len=:), allocatable :: path, text
      integer, allocatable :: first(:), last(:), line(:)
      integer :: n = 0, last_line = 0, first_height = 0
      integer :: start(2:5) = 0, count(2:5) = 0
   end type deck_tokens

contains

   !> Read and validate a deck. On error `status` holds `path:line: expected ..., found ...`
   !> and `deck` is left unspecified.
   subroutine read_deck(path, deck, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(deck_tokens) :: t
      integer :: i, j, header_end
      logical :: ok
      ! An HDF5 deck (femcod_deck_h5) by its signature, whatever its name.
      if (is_hdf5_file(path)) then
         call read_deck_h5(path, deck, status)
         return
      end if
      t%path = path
      call read_file(path, "a deck file", t%text, status)
      if (status%code /= 0) then
         if (index(status%message, "empty file") > 0) status%message = path//":1: expected a label line, found an "// &
            "empty file"
         return
      end if
      call check_text(path, t%text, status)
      if (status%code /= 0) return
      ! Lines 1 to 5 are tokenized here, the heights parsed straight from the text
      ! (heights_from_text); only a deck whose heights are refused is tokenized whole,
      ! for the message. A text of fewer than five lines is tokenized whole at once.
      header_end = 0
      do i = 1, 5
         j = index(t%text(header_end + 1:), new_line("a"))
         if (j == 0) then
            header_end = len(t%text)
            exit
         end if
         header_end = header_end + j
      end do
      call tokenize(t%text(1:header_end), t%n, t%first, t%last, t%line, t%last_line)
      deck%label = label_of(t%text)
      call read_header_values(t, deck, status)
      if (status%code /= 0) return
      allocate(deck%lower(deck%np, deck%np), deck%upper(deck%np, deck%np))
      if (header_end < len(t%text) .and. words_little_endian()) then
         call heights_from_text(t%text, header_end + 1, deck%lower, deck%upper, ok)
         if (ok) return
      end if
      if (header_end < len(t%text)) then
         ! The whole text: its first tokens are those of lines 1 to 5 found above (they
         ! end at a line end), the heights follow.
         t%first_height = t%n + 1
         call tokenize(t%text, t%n, t%first, t%last, t%line, t%last_line)
      end if
      call read_height_tokens(t, deck, status)
   end subroutine read_deck

   !> The header of a text deck, `text` (its lines 1 to 5 with their line ends, or the
   !> whole file when it has fewer), checked and read as read_deck reads it: the label,
   !> NP PIXEL MAXCONT and the three materials, with read_deck's messages; no heights.
   !> For a reader that takes the heights in slabs (femcod_deck_stream).
   subroutine read_deck_header(path, text, deck, status)
      character(len=*), intent(in) :: path, text
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(deck_tokens) :: t
      t%path = path
      t%text = text
      call check_text(path, t%text, status)
      if (status%code /= 0) return
      call tokenize(t%text, t%n, t%first, t%last, t%line, t%last_line)
      deck%label = label_of(t%text)
      call read_header_values(t, deck, status)
   end subroutine read_deck_header

   !> Lines 2 to 5: exactly the named values (NP PIXEL MAXCONT, then each material's E
   !> and NU), each within its range.
   subroutine read_header_values(t, deck, status)
      type(deck_tokens), intent(inout) :: t
      type(contact_problem), intent(inout) :: deck
      type(status_type), intent(inout) :: status
      integer :: k, i
      t%count = 0
      t%start = 0
      t%first_height = t%n + 1
      do k = 1, t%n
         if (t%line(k) >= 6) then
            t%first_height = k
            exit
         end if
         if (t%line(k) >= 2) then
            if (t%count(t%line(k)) == 0) t%start(t%line(k)) = k
            t%count(t%line(k)) = t%count(t%line(k)) + 1
         end if
      end do
      call expect_count(t, 2, 3, "NP PIXEL MAXCONT", status)
      if (status%code /= 0) return
      call get_int(t, t%start(2), "NP, a positive integer", deck%np, status)
      if (status%code /= 0) return
      if (deck%np <= 0 .or. deck%np > MAX_NP) then
         call refuse_token(t, 2, "NP, an integer from 1 to "//int_str(MAX_NP), t%start(2), status)
         return
      end if
      call get_real(t, t%start(2) + 1, "PIXEL, the pixel size in nm (1e-6 to 1e6)", deck%pixel, status)
      if (status%code /= 0) return
      if (.not. (deck%pixel >= MIN_PIXEL .and. deck%pixel <= MAX_PIXEL)) then
         call refuse_token(t, 2, "PIXEL, the pixel size in nm (1e-6 to 1e6)", t%start(2) + 1, status)
         return
      end if
      call get_int(t, t%start(2) + 2, "MAXCONT, a positive integer", deck%maxcont, status)
      if (status%code /= 0) return
      if (deck%maxcont <= 0 .or. deck%maxcont > deck%np**2) then
         call refuse_token(t, 2, "MAXCONT, an integer from 1 to NP**2 = "//int_str(deck%np**2), t%start(2) + 2, &
            status)
         return
      end if
      do i = 1, 3
         call read_material(t, i, deck%young(i), deck%poisson(i), status)
         if (status%code /= 0) return
      end do
   end subroutine read_header_values

   !> Line 2 + i: E and NU of material i (GPa, dimensionless), each within its range.
   subroutine read_material(t, i, young, poisson, status)
      type(deck_tokens), intent(in) :: t
      integer, intent(in) :: i
      real(dp), intent(out) :: young, poisson
      type(status_type), intent(inout) :: status
      call expect_count(t, 2 + i, 2, "E"//int_str(i)//" NU"//int_str(i)//" of the "//trim(material_names(i)), status)
      if (status%code /= 0) return
      call get_real(t, t%start(2 + i), "E"//int_str(i)//", Young's modulus in GPa (1e-12 to 1e300)", young, status)
      if (status%code /= 0) return
      if (.not. (young >= MIN_YOUNG .and. young <= MAX_YOUNG)) then
         call refuse_token(t, 2 + i, "E"//int_str(i)//", Young's modulus in GPa (1e-12 to 1e300)", t%start(2 + i), &
            status)
         return
      end if
      call get_real(t, t%start(2 + i) + 1, "NU"//int_str(i)//", Poisson's ratio in (-1, 0.5)", poisson, status)
      if (status%code /= 0) return
      if (.not. (poisson > -1 .and. poisson < 0.5_dp)) call refuse_token(t, 2 + i, "NU"//int_str(i)// &
         ", Poisson's ratio in (-1, 0.5)", t%start(2 + i) + 1, status)
   end subroutine read_material

   !> The 2 NP^2 heights from the tokens of line 6 on: exactly that many, each a finite
   !> number within 1e12 nm.
   subroutine read_height_tokens(t, deck, status)
      type(deck_tokens), intent(in) :: t
      type(contact_problem), intent(inout) :: deck
      type(status_type), intent(inout) :: status
      integer(i8) :: nvalues
      character(len=24) :: count_text
      integer :: k
      ! In 64 bits: 2 NP**2 overflows a default integer for NP > 32767.
      nvalues = 2*int(deck%np, i8)**2
      write(count_text, '(i0)') nvalues
      if (t%n - t%first_height + 1 < nvalues) then
         call set_error(status, STATUS_BAD_INPUT, t%path//":"//int_str(t%last_line)//": expected "// &
            trim(count_text)//" heights (NP**2 = "//int_str(deck%np**2)//" lower, then as many upper), found "// &
            int_str(t%n - t%first_height + 1)//" before the end of the file")
         return
      end if
      if (t%n - t%first_height + 1 > nvalues) then
         k = t%first_height + int(nvalues)
         call refuse_token(t, t%line(k), "the end of the deck after the "//trim(count_text)//" heights", k, status)
         return
      end if
      ! The message of a bad height is built only when there is one: a string per value
      ! made reading a 1024 x 1024 deck allocation-bound.
      k = t%first_height
      call get_heights(t, k, deck%lower, "a lower-surface height", status)
      if (status%code /= 0) return
      call get_heights(t, k, deck%upper, "an upper-surface height", status)
   end subroutine read_height_tokens

   !> Token k as a message shows it: quoted, at most 40 characters.
   function token_text(t, k) result(s)
      type(deck_tokens), intent(in) :: t
      integer, intent(in) :: k
      character(len=:), allocatable :: s
      s = "'"//t%text(t%first(k):min(t%last(k), t%first(k) + 39))//"'"
      if (t%last(k) - t%first(k) > 39) s = s//"..."
   end function token_text

   !> `path:line: expected <expected>, found <token k>`.
   subroutine refuse_token(t, line, expected, k, status)
      type(deck_tokens), intent(in) :: t
      integer, intent(in) :: line, k
      character(len=*), intent(in) :: expected
      type(status_type), intent(inout) :: status
      call refuse_found(t, line, expected, token_text(t, k), status)
   end subroutine refuse_token

   subroutine refuse_found(t, line, expected, found, status)
      type(deck_tokens), intent(in) :: t
      integer, intent(in) :: line
      character(len=*), intent(in) :: expected, found
      type(status_type), intent(inout) :: status
      call set_error(status, STATUS_BAD_INPUT, t%path//":"//int_str(line)//": expected "//expected//", found "//found)
   end subroutine refuse_found

   !> Line `line` holds exactly n values (`what`).
   subroutine expect_count(t, line, n, what, status)
      type(deck_tokens), intent(in) :: t
      integer, intent(in) :: line, n
      character(len=*), intent(in) :: what
      type(status_type), intent(inout) :: status
      if (t%count(line) == n) return
      if (t%last_line < line) then
         call set_error(status, STATUS_BAD_INPUT, t%path//":"//int_str(line)//": expected "//int_str(n)// &
            " values ("//what//"), found the end of the file")
      else
         call refuse_found(t, line, int_str(n)//" values ("//what//")", count_text(t%count(line), "value"), status)
      end if
   end subroutine expect_count

   subroutine get_int(t, k, what, value, status)
      type(deck_tokens), intent(in) :: t
      integer, intent(in) :: k
      character(len=*), intent(in) :: what
      integer, intent(out) :: value
      type(status_type), intent(inout) :: status
      logical :: ok
      call parse_integer(t%text(t%first(k):t%last(k)), value, ok)
      if (.not. ok) call refuse_token(t, t%line(k), what, k, status)
   end subroutine get_int

   subroutine get_real(t, k, what, value, status)
      type(deck_tokens), intent(in) :: t
      integer, intent(in) :: k
      character(len=*), intent(in) :: what
      real(dp), intent(out) :: value
      type(status_type), intent(inout) :: status
      logical :: ok
      call parse_real(t%text(t%first(k):t%last(k)), value, ok)
      if (.not. ok) call refuse_token(t, t%line(k), what//" (a finite number)", k, status)
   end subroutine get_real

   !> The NP x NP heights from token k on, row by row; k ends past them. The values are
   !> converted in parallel; the first bad one (in file order) is reported.
   subroutine get_heights(t, k, z, what, status)
      type(deck_tokens), intent(in) :: t
      integer, intent(inout) :: k
      real(dp), intent(out) :: z(:, :)
      character(len=*), intent(in) :: what
      type(status_type), intent(inout) :: status
      integer :: i, j, m, ncol, first_bad
      logical :: ok
      ncol = size(z, 2)
      first_bad = huge(first_bad)
      !$omp parallel do private(i, j, m, ok) reduction(min: first_bad) schedule(static)
      do i = 1, size(z, 1)
         do j = 1, ncol
            m = k + (i - 1)*ncol + j - 1
            call parse_real(t%text(t%first(m):t%last(m)), z(i, j), ok)
            if (ok) ok = abs(z(i, j)) <= MAX_HEIGHT
            if (.not. ok) first_bad = min(first_bad, m)
         end do
      end do
      !$omp end parallel do
      if (first_bad < huge(first_bad)) then
         m = first_bad
         i = (m - k)/ncol + 1
         j = m - k - (i - 1)*ncol + 1
         call parse_real(t%text(t%first(m):t%last(m)), z(i, j), ok)
         if (.not. ok) then
            call refuse_token(t, t%line(m), what//" in nm (row "//int_str(i)//", column "//int_str(j)//") (a finite "// &
               "number)", m, status)
         else
            call refuse_token(t, t%line(m), "a height within 1e12 nm (row "//int_str(i)//", column "//int_str(j)//")", &
               m, status)
         end if
         return
      end if
      k = k + size(z)
   end subroutine get_heights

   !> Write a deck: validated first, written under a temporary name, then renamed, so
   !> that `path` is either untouched or complete. Each real is written with the fewest
   !> digits that read back to the same double, one image row per line.
   subroutine write_deck(path, deck, status, max_bytes)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(in) :: deck
      type(status_type), intent(inout) :: status
      !> The largest deck written (bytes; default and at most MAX_TEXT_BYTES, the most
      !> read_deck reads): a larger one is refused and nothing is written.
      integer, intent(in), optional :: max_bytes
      type(text_builder) :: b
      integer :: i, limit
      ! A name ending in .h5: the HDF5 deck (femcod_deck_h5), any size.
      if (len(path) >= 3) then
         if (path(len(path) - 2:) == ".h5") then
            call write_deck_h5(path, deck, status)
            return
         end if
      end if
      limit = MAX_TEXT_BYTES
      if (present(max_bytes)) limit = min(max_bytes, MAX_TEXT_BYTES)
      call validate_problem(deck, status)
      if (status%code /= 0) return
      call add_line(b, deck%label)
      call add_line(b, int_str(deck%np)//" "//format_real(deck%pixel)//" "//int_str(deck%maxcont))
      do i = 1, 3
         call add_line(b, format_real(deck%young(i))//" "//format_real(deck%poisson(i)))
      end do
      do i = 1, deck%np
         call add_row(deck%lower(i, :))
      end do
      do i = 1, deck%np
         call add_row(deck%upper(i, :))
      end do
      if (status%code /= 0) return
      call write_file(path, built_text(b), status)
   contains
      !> One image row on one line, the values separated by blanks; refused (and nothing
      !> written) when the deck would pass `limit`.
      subroutine add_row(row)
         real(dp), intent(in) :: row(:)
         character(len=24), allocatable :: texts(:)
         integer, allocatable :: lengths(:)
         integer :: j
         if (status%code /= 0) return
         call format_reals(row, texts, lengths)
         if (int(b%length, i8) + sum(int(lengths, i8)) + size(row) > limit) then
            call set_error(status, STATUS_USAGE, path//": a deck of NP = "//int_str(deck%np)//" with these "// &
               "heights is more than "//int_str(limit)//" bytes, the most a deck is written and read with; "// &
               "give the surfaces as an HDF5 dataset (femcod run --lower FILE.h5:/DATASET)")
            return
         end if
         call add_text(b, texts(1)(1:lengths(1)))
         do j = 2, size(row)
            call add_text(b, " "//texts(j)(1:lengths(j)))
         end do
         call add_text(b, new_line("a"))
      end subroutine add_row
   end subroutine write_deck

   !> The NP x NP lower heights then the NP x NP upper ones (nm), row by row, from
   !> text(start:) to its end, parsed where they stand: no token arrays (at 1024^2 three
   !> of 2 million integers, written and read back). The text is cut at separators into
   !> blocks of 256 KiB; the threads count each block's tokens (femcod_bytes), then, from
   !> the counts before it, each block's tokens are found again into a small buffer and
   !> converted. `ok` is false, and the caller tokenizes the whole deck for the message,
   !> when the count is not 2 NP^2 or a value is not a number within MAX_HEIGHT.
   subroutine heights_from_text(text, start, lower, upper, ok)
      character(len=*), intent(in) :: text
      integer, intent(in) :: start
      real(dp), intent(out) :: lower(:, :), upper(:, :)
      logical, intent(out) :: ok
      integer, parameter :: BLOCK_BYTES = 262144
      integer, allocatable :: bounds(:), counts(:), first(:), last(:)
      integer(i8), allocatable :: before(:)
      integer(i8) :: m, per_surface
      integer :: nblocks, b, p, n, t, count, ends, np, i, j, bad
      real(dp) :: v
      logical :: good
      n = len(text)
      np = size(lower, 1)
      per_surface = int(np, i8)**2
      nblocks = max(1, (n - start + 1)/BLOCK_BYTES)
      allocate(bounds(0:nblocks), counts(nblocks), before(nblocks))
      bounds(0) = start - 1
      do b = 1, nblocks - 1
         p = max(bounds(b - 1), start - 1 + int(int(n - start + 1, i8)*b/nblocks))
         do while (p < n)
            if (iachar(text(p:p)) < 33 .or. text(p:p) == ",") exit
            p = p + 1
         end do
         bounds(b) = p
      end do
      bounds(nblocks) = n
      !$omp parallel do schedule(static)
      do b = 1, nblocks
         counts(b) = count_tokens(text, bounds(b - 1) + 1, bounds(b))
      end do
      before(1) = 0
      do b = 2, nblocks
         before(b) = before(b - 1) + counts(b - 1)
      end do
      ok = before(nblocks) + counts(nblocks) == 2*per_surface
      if (.not. ok) return
      bad = 0
      !$omp parallel private(first, last, count, ends, t, m, i, j, v, good) reduction(+: bad)
      allocate(first(maxval(counts)), last(maxval(counts)))
      !$omp do schedule(static)
      do b = 1, nblocks
         call scan_tokens(text, bounds(b - 1) + 1, bounds(b), 0, 0, count, ends, first, last)
         ! Row i, column j of the height number before(b) + 1 of its surface.
         m = mod(before(b), per_surface)
         i = int(m/np) + 1
         j = int(m - (i - 1)*int(np, i8)) + 1
         m = before(b)
         do t = 1, count
            call parse_real(text(first(t):last(t)), v, good)
            if (good) good = abs(v) <= MAX_HEIGHT
            if (.not. good) bad = bad + 1
            m = m + 1
            if (m <= per_surface) then
               lower(i, j) = v
            else
               upper(i, j) = v
            end if
            j = j + 1
            if (j > np) then
               j = 1
               i = i + 1
               if (i > np) i = 1
            end if
         end do
      end do
      !$omp end do
      !$omp end parallel
      ok = bad == 0
   end subroutine heights_from_text

   !> Refuse what is not a text deck: UTF-16 (a byte order mark, or NUL bytes between
   !> the characters), and binary content (control bytes other than TAB, LF, CR and FF).
   !> A UTF-8 byte order mark is dropped (editors on some systems write one).
   subroutine check_text(path, text, status)
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(inout) :: text
      type(status_type), intent(inout) :: status
      logical :: control(0:255)
      integer :: i, line, c, first
      if (len(text) >= 3) then
         if (text(1:3) == achar(239)//achar(187)//achar(191)) text = text(4:)
      end if
      if (len(text) >= 2) then
         if (text(1:2) == achar(255)//achar(254) .or. text(1:2) == achar(254)//achar(255) .or. &
            (len(text) >= 4 .and. (text(2:2) == achar(0) .and. text(4:4) == achar(0) .or. &
            text(1:1) == achar(0) .and. text(3:3) == achar(0)))) then
            call set_error(status, STATUS_BAD_INPUT, path//":1: expected a text deck in ASCII or UTF-8, found "// &
               "UTF-16 text (convert it, for example: iconv -f UTF-16 -t UTF-8 "//path//" > deck.txt)")
            return
         end if
      end if
      ! The first control byte, looked for on all threads; its line only if there is one.
      control = .false.
      control(0:31) = .true.
      control([9, 10, 12, 13]) = .false.
      control(127) = .true.
      first = huge(first)
      if (words_little_endian()) then
         first = first_control_byte(text)
      else
         !$omp parallel do reduction(min: first) schedule(static)
         do i = 1, len(text)
            if (control(iachar(text(i:i)))) first = min(first, i)
         end do
      end if
      if (first == huge(first)) return
      c = iachar(text(first:first))
      line = 1
      do i = 1, first - 1
         if (text(i:i) == new_line("a")) line = line + 1
      end do
      call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(line)// &
         ": expected a text deck, found a binary control character (code "//int_str(c)//") at byte "//int_str(first))
   end subroutine check_text

   !> The first line without its line end.
   function label_of(text) result(label)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: label
      integer :: e
      e = index(text, new_line("a"))
      if (e == 0) e = len(text) + 1
      label = text(1:e - 1)
      if (len(label) > 0) then
         if (label(len(label):len(label)) == achar(13)) label = label(1:len(label) - 1)
      end if
      label = trim(label)
   end function label_of

   !> Split everything after line 1 into tokens separated by blanks, tabs, CR, FF or
   !> commas, recording the line of each token and the number of the last line. The text
   !> is cut at separators into one segment per thread; each thread counts its segment's
   !> tokens and line ends, then (from the counts before it) records its tokens. Eight
   !> bytes are classified at a time (femcod_bytes; check_text has refused every control
   !> byte but TAB, LF, FF and CR before, so the separators are the bytes below 33 and the
   !> comma), and the tokens' starts and ends are the bits where a separator and another
   !> byte meet: 0.055 to 0.070 s -> 0.021 to 0.033 s for a 1024^2 deck (21 MB) on 2
   !> threads. Byte by byte (a table of separators) where words are not little-endian.
   subroutine tokenize(text, ntok, first, last, line, last_line)
      character(len=*), intent(in) :: text
      integer, intent(out) :: ntok, last_line
      integer, allocatable, intent(out) :: first(:), last(:), line(:)
      logical :: separator(0:255)
      integer, allocatable :: bounds(:), tokens(:), lines(:), token0(:), line0(:)
      integer :: nseg, s, p, n, start, count, ends
      logical :: by_words
      separator = .false.
      separator([9, 10, 12, 13, 32, 44]) = .true.
      n = len(text)
      start = index(text, new_line("a"))
      if (start == 0) start = n
      ! Segment s is text(bounds(s - 1) + 1 : bounds(s)); each bound but the last is a
      ! separator, so no token crosses one.
      nseg = 1
      !$ nseg = omp_get_max_threads()
      nseg = max(1, min(nseg, (n - start)/65536))
      allocate(bounds(0:nseg), tokens(nseg), lines(nseg))
      bounds(0) = start
      do s = 1, nseg - 1
         p = max(bounds(s - 1), start + int(int(n - start, i8)*s/nseg))
         do while (p < n)
            if (separator(iachar(text(p:p)))) exit
            p = p + 1
         end do
         bounds(s) = p
      end do
      bounds(nseg) = n
      by_words = words_little_endian()
      !$omp parallel do schedule(static, 1)
      do s = 1, nseg
         if (by_words) then
            call scan_tokens(text, bounds(s - 1) + 1, bounds(s), 0, 0, tokens(s), lines(s))
         else
            call scan_segment(bounds(s - 1) + 1, bounds(s), 0, 0, tokens(s), lines(s), .false.)
         end if
      end do
      ntok = sum(tokens)
      allocate(first(ntok), last(ntok), line(ntok), token0(nseg), line0(nseg))
      do s = 1, nseg
         token0(s) = sum(tokens(1:s - 1))
         line0(s) = 2 + sum(lines(1:s - 1))
      end do
      !$omp parallel do schedule(static, 1) private(count, ends)
      do s = 1, nseg
         if (by_words) then
            call scan_tokens(text, bounds(s - 1) + 1, bounds(s), token0(s), line0(s), count, ends, first, last, line)
         else
            call scan_segment(bounds(s - 1) + 1, bounds(s), token0(s), line0(s), count, ends, .true.)
         end if
      end do
      ! The number of the last line that holds anything.
      last_line = 2 + sum(lines)
      if (n > 0) then
         if (text(n:n) == new_line("a")) last_line = last_line - 1
      end if
      if (index(text, new_line("a")) == 0) last_line = 1
   contains
      !> Tokens and line ends of text(i0:i1): counted, and with `record` recorded from
      !> token number k0 + 1 and line ln0 on.
      subroutine scan_segment(i0, i1, k0, ln0, count, ends, record)
         integer, intent(in) :: i0, i1, k0, ln0
         integer, intent(out) :: count, ends
         logical, intent(in) :: record
         integer :: i, c, k, ln
         logical :: inside
         k = k0
         ln = ln0
         ends = 0
         inside = .false.
         do i = i0, i1
            c = iachar(text(i:i))
            if (separator(c)) then
               if (inside .and. record) last(k) = i - 1
               inside = .false.
               if (c == 10) then
                  ln = ln + 1
                  ends = ends + 1
               end if
            else if (.not. inside) then
               inside = .true.
               k = k + 1
               if (record) then
                  first(k) = i
                  line(k) = ln
               end if
            end if
         end do
         if (inside .and. record) last(k) = i1
         count = k - k0
      end subroutine scan_segment
   end subroutine tokenize

end module femcod_deck
