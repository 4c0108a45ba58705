!> Deck reading, writing and validation: every bad deck is refused with its file, line
!> and what was expected (doc/deck-format.md).
module test_deck
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error
   use femcod_deck, only: read_deck, write_deck
   use femcod_deck_stream, only: deck_stream, open_deck_stream, read_deck_heights, close_deck_stream, open_deck_range, &
      count_deck_range, separator_at_or_after, binary_byte, balanced_cuts
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, format_real, format_reals, int_str, parse_real
   use femcod_cli, only: run_femcod
   use femcod_bytes, only: words_little_endian, first_control_byte, scan_tokens, count_tokens, eight_digits
   use test_support, only: write_text, scratch_path, contains_text, file_exists, read_text
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_deck

   character(len=*), parameter :: nl = new_line("a")
   !> A valid 2x2 deck; the cases below break one thing at a time.
   character(len=*), parameter :: header = "two by two"//nl//"2 1.5 3"//nl//"200 0.25"//nl// &
      "2e7 0.25"//nl//"2e7 0.3"//nl
   character(len=*), parameter :: heights = "0 0.5"//nl//"1 1.5"//nl//"2 2.5 3 3.5"//nl

contains

   subroutine collect_deck(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("valid deck: values and layout", test_valid), &
         new_unittest("CRLF, tabs, commas, D exponents, wrapped values", test_formats), &
         new_unittest("write then read is exact", test_roundtrip), &
         new_unittest("a 300 x 300 deck of mixed separators reads exactly; its bad values are named", test_large_deck), &
         new_unittest("shortest round-trip number format", test_format_real), &
         new_unittest("format_real equals a brute-force search on 40000 values", test_format_real_search), &
         new_unittest("parse_real equals Fortran's READ on 60000 decimals and halfway cases", test_parse_real), &
         new_unittest("int_str equals Fortran's i0 edit descriptor", test_int_str), &
         new_unittest("eight-byte scans equal byte-by-byte scans on 3000 random texts", test_word_scans), &
         new_unittest("eight digits at once: values as READ gives them, every neighbour byte refused", test_eight_digits), &
         new_unittest("the first bad height in file order is reported", test_first_bad_height), &
         new_unittest("bad deck: "//"missing value line 2", bad_01), &
         new_unittest("bad deck: "//"extra value line 3", bad_02), &
         new_unittest("bad deck: "//"non-numeric height", bad_03), &
         new_unittest("bad deck: "//"NaN height", bad_04), &
         new_unittest("bad deck: "//"Inf height", bad_05), &
         new_unittest("bad deck: "//"overflowing height", bad_06), &
         new_unittest("bad deck: "//"NP zero", bad_07), &
         new_unittest("bad deck: "//"NP negative", bad_08), &
         new_unittest("bad deck: "//"NP not an integer", bad_09), &
         new_unittest("bad deck: "//"NP overflowing", bad_10), &
         new_unittest("bad deck: "//"PIXEL zero", bad_11), &
         new_unittest("bad deck: "//"PIXEL negative", bad_12), &
         new_unittest("bad deck: "//"MAXCONT zero", bad_13), &
         new_unittest("bad deck: "//"MAXCONT above NP**2", bad_14), &
         new_unittest("bad deck: "//"E zero", bad_15), &
         new_unittest("bad deck: "//"E negative", bad_16), &
         new_unittest("bad deck: "//"nu = 0.5", bad_17), &
         new_unittest("bad deck: "//"nu = -1", bad_18), &
         new_unittest("bad deck: "//"truncated heights", bad_19), &
         new_unittest("bad deck: "//"trailing values", bad_20), &
         new_unittest("bad deck: "//"binary content", bad_21), &
         new_unittest("bad deck: "//"header cut short", bad_22), &
         new_unittest("missing file, directory, empty file", test_bad_files), &
         new_unittest("a deck above 2 GiB less 64 KiB is refused before it is read", test_huge_deck), &
         new_unittest("a deck beyond the writer's limit is refused and not written", test_deck_limit), &
         new_unittest("bad deck through femcod run: exit 3, no result file", test_run_bad_deck), &
         new_unittest("a UTF-8 byte order mark is not part of the label", test_bom), &
         new_unittest("streamed in slabs: the same heights and messages, cut anywhere", test_stream), &
         new_unittest("read by ranges of bytes (femcod-mpi's ranks): the same heights and messages", test_ranges), &
         new_unittest("blocks of work cut into parts of about equal weight", test_balanced_cuts) &
         ]
   end subroutine collect_deck

   subroutine test_valid(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path
      path = scratch_path("valid.deck")
      call write_text(path, header//heights)
      call read_deck(path, deck, status)
      call check(error, status%code, 0, "a valid deck is accepted")
      if (allocated(error)) return
      call check(error, deck%label, "two by two")
      if (allocated(error)) return
      call check(error, deck%np, 2)
      if (allocated(error)) return
      call check(error, deck%maxcont, 3)
      if (allocated(error)) return
      call check(error, deck%pixel, 1.5_dp)
      if (allocated(error)) return
      call check(error, deck%young(3), 2.0e7_dp)
      if (allocated(error)) return
      call check(error, deck%poisson(3), 0.3_dp)
      if (allocated(error)) return
      ! Row by row: lower(1,2) is the second value, upper(2,1) the seventh.
      call check(error, deck%lower(1, 2), 0.5_dp)
      if (allocated(error)) return
      call check(error, deck%lower(2, 1), 1.0_dp)
      if (allocated(error)) return
      call check(error, deck%upper(2, 1), 3.0_dp)
   end subroutine test_valid

   subroutine test_formats(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path
      character(len=*), parameter :: cr = achar(13), tab = achar(9)
      path = scratch_path("formats.deck")
      call write_text(path, "crlf deck"//cr//nl//"2"//tab//"1.5D0 3"//cr//nl//"2.0d2 0.25"//cr//nl// &
         "2E7,0.25"//cr//nl//"+2e+7 .3"//cr//nl//"0"//cr//nl//"0.5 1"//cr//nl//cr//nl//tab//"1.5 2 2.5"// &
         cr//nl//"3"//nl//"3.5")
      call read_deck(path, deck, status)
      call check(error, status%code, 0, "CRLF, tabs, commas, D exponents and wrapped values are accepted")
      if (allocated(error)) return
      call check(error, deck%label, "crlf deck")
      if (allocated(error)) return
      call check(error, deck%pixel, 1.5_dp)
      if (allocated(error)) return
      call check(error, deck%young(1), 200.0_dp)
      if (allocated(error)) return
      call check(error, deck%poisson(3), 0.3_dp)
      if (allocated(error)) return
      call check(error, deck%upper(2, 2), 3.5_dp)
   end subroutine test_formats

   subroutine test_roundtrip(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck, back
      type(status_type) :: status
      character(len=:), allocatable :: path
      integer :: i, j
      deck%label = "round trip"
      deck%np = 3
      deck%pixel = 1.0_dp/3
      deck%maxcont = 9
      deck%young = [200.0_dp, 2.0e7_dp, 123.456_dp]
      deck%poisson = [0.25_dp, -0.5_dp, 0.499_dp]
      allocate(deck%lower(3, 3), deck%upper(3, 3))
      do j = 1, 3
         do i = 1, 3
            deck%lower(i, j) = sqrt(real(i + 10*j, dp))*1.0e-7_dp
            deck%upper(i, j) = -exp(real(i*j, dp))*1.0e5_dp
         end do
      end do
      path = scratch_path("roundtrip.deck")
      call write_deck(path, deck, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call read_deck(path, back, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call check(error, all(back%lower == deck%lower) .and. all(back%upper == deck%upper) .and. &
         back%pixel == deck%pixel .and. all(back%young == deck%young) .and. all(back%poisson == deck%poisson), &
         "every value reads back bit for bit")
   end subroutine test_roundtrip

   !> A deck of 2 x 300^2 random heights (about 4 MB, many of the reader's 256 KiB blocks),
   !> each written with 17 significant digits (which name one double: READ of the
   !> same text is the expected value) and separated at random by blanks, tabs, commas,
   !> LF or CRLF: every value reads back bit for bit. Then the last value made "x", and
   !> one value more: refused with the line the test counted while writing.
   subroutine test_large_deck(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 300
      character(len=*), parameter :: separators(5) = [character(len=2) :: " ", achar(9), ",", nl, achar(13)//nl]
      integer, parameter :: lengths(5) = [1, 1, 1, 1, 2]
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path, text, body
      character(len=25) :: t
      real(dp), allocatable :: values(:)
      real(dp) :: u
      integer :: k, line, last_line, last_start, sep, n
      allocate(values(2*np*np))
      allocate(character(len=27*size(values)) :: body)
      n = 0
      line = 6
      do k = 1, size(values)
         call random_number(u)
         write(t, "(es25.16e3)") (u - 0.5_dp)*10.0_dp**(mod(k, 9) - 4)
         t = adjustl(t)
         read(t, *) values(k)
         if (k > 1) then
            call random_number(u)
            sep = 1 + int(u*size(separators))
            if (sep >= 4) line = line + 1
            body(n + 1:n + lengths(sep)) = separators(sep)(1:lengths(sep))
            n = n + lengths(sep)
         end if
         last_start = n + 1
         body(n + 1:n + len_trim(t)) = trim(t)
         n = n + len_trim(t)
      end do
      body = body(1:n)
      last_line = line
      text = "large"//nl//int_str(np)//" 2.5 100"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl
      path = scratch_path("large.deck")
      call write_text(path, text//body//nl)
      call read_deck(path, deck, status)
      call check(error, status%code, 0, "a valid 300 x 300 deck is accepted: "//status%message)
      if (allocated(error)) return
      call check(error, all(transfer(reshape(transpose(deck%lower), [np*np]), 1_8, np*np) == &
         transfer(values(1:np*np), 1_8, np*np)) .and. all(transfer(reshape(transpose(deck%upper), [np*np]), 1_8, &
         np*np) == transfer(values(np*np + 1:), 1_8, np*np)), "every height reads back bit for bit, row by row")
      if (allocated(error)) return
      call write_text(path, text//body(1:last_start - 1)//"x"//nl)
      status = status_type()
      call read_deck(path, deck, status)
      call check(error, status%code /= 0 .and. contains_text(status%message, "large.deck:"//int_str(last_line)// &
         ": expected an upper-surface height in nm (row 300, column 300)"), "the bad last value is named "// &
         "with its line: "//status%message)
      if (allocated(error)) return
      call write_text(path, text//body//" 1"//nl)
      status = status_type()
      call read_deck(path, deck, status)
      call check(error, status%code /= 0 .and. contains_text(status%message, "large.deck:"//int_str(last_line)// &
         ": expected the end of the deck after the 180000 heights, found '1'"), "one value more is refused "// &
         "with its line: "//status%message)
   end subroutine test_large_deck

   subroutine test_format_real(error)
      use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf, ieee_negative_inf
      type(error_type), allocatable, intent(out) :: error
      call check(error, format_real(200.0_dp), "200")
      if (allocated(error)) return
      call check(error, format_real(0.25_dp), "0.25")
      if (allocated(error)) return
      call check(error, format_real(2.0e7_dp), "2e7")
      if (allocated(error)) return
      call check(error, format_real(-1.5e-9_dp), "-1.5e-9")
      if (allocated(error)) return
      call check(error, format_real(0.0_dp), "0")
      if (allocated(error)) return
      ! Not a number and the infinities as Python's float() reads them (a friction
      ! coefficient without contact is NaN; the digits of its bits were once written).
      call check(error, format_real(ieee_value(1.0_dp, ieee_quiet_nan)), "nan")
      if (allocated(error)) return
      call check(error, format_real(ieee_value(1.0_dp, ieee_positive_inf)), "inf")
      if (allocated(error)) return
      call check(error, format_real(ieee_value(1.0_dp, ieee_negative_inf)), "-inf")
   end subroutine test_format_real

   !> format_real against the definition, searched by brute force with Fortran's own
   !> formatted I/O (independent of the C conversions format_real uses): the fewest
   !> significant digits (es, p = 0..16) whose decimal reads back to x; the positional
   !> form (f0.q, q = 0..20) with the fewest decimals that reads back, when 1e-4 <= |x|
   !> < 1e15 and not longer. Values: random mantissas at every decade from 1e-310 to
   !> 1e308, random bit patterns, and the edges (powers of 2 and 10, 1 - ulp, the bounds
   !> of the positional range, the largest and smallest doubles).
   subroutine test_format_real_search(error)
      use, intrinsic :: ieee_exceptions, only: ieee_overflow, ieee_get_halting_mode, ieee_set_halting_mode, &
         ieee_set_flag
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: values(:)
      real(dp) :: u
      integer(8) :: bits
      integer :: k, e, nseed
      integer, allocatable :: seed(:), lengths(:)
      character(len=24), allocatable :: texts(:)
      character(len=:), allocatable :: expected
      logical :: halting
      allocate(values(0))
      values = [values, 1.0_dp, 0.1_dp, 1.0e-4_dp, nearest(1.0e-4_dp, -1.0_dp), 1.0e15_dp, nearest(1.0e15_dp, -1.0_dp), &
         nearest(1.0_dp, -1.0_dp), nearest(1.0_dp, 2.0_dp), huge(1.0_dp), tiny(1.0_dp), tiny(1.0_dp)/2**20, &
         9007199254740993.0_dp, tiny(1.0_dp)*epsilon(1.0_dp), 123456789012345678.0_dp, 0.3_dp, 2.0_dp/3, &
         1200.0_dp, 9.5_dp, 999.9999999_dp]
      do e = -300, 300, 7
         values = [values, 10.0_dp**real(e, dp), 2.0_dp**real(e*3, dp)]
      end do
      call random_seed(size=nseed)
      allocate(seed(nseed))
      seed = 20261123
      call random_seed(put=seed)
      do k = 1, 30000
         call random_number(u)
         e = -310 + mod(k*37, 618)
         values = [values, (u + 0.1_dp)*10.0_dp**real(e, dp)*merge(1, -1, mod(k, 3) /= 0)]
      end do
      do k = 1, 10000
         call random_number(u)
         bits = int(u*huge(1_8), 8)
         ! Finite doubles only (an exponent field of all ones is Inf or NaN).
         if (ibits(bits, 52, 11) == 2047) cycle
         values = [values, transfer(bits, 1.0_dp)]
      end do
      ! The brute force reads decimals rounded up past the largest double: overflow is
      ! expected there and must not trap (fpm @strict traps it).
      call ieee_get_halting_mode(ieee_overflow, halting)
      call ieee_set_halting_mode(ieee_overflow, .false.)
      ! format_reals converts the same values in parallel threads (gfortran once made
      ! that race): each must equal the search too.
      call format_reals(values, texts, lengths)
      do k = 1, size(values)
         expected = shortest_by_search(values(k))
         call check(error, format_real(values(k)), expected, "format_real of value "//to_string(k))
         if (allocated(error)) exit
         call check(error, texts(k)(1:lengths(k)), expected, "format_reals of value "//to_string(k))
         if (allocated(error)) exit
      end do
      call ieee_set_flag(ieee_overflow, .false.)
      call ieee_set_halting_mode(ieee_overflow, halting)
   contains
      function shortest_by_search(x) result(s)
         real(dp), intent(in) :: x
         character(len=:), allocatable :: s
         character(len=48) :: buf, fmt
         real(dp) :: back
         integer :: p, ios, ex, last
         if (x == 0) then
            s = "0"
            return
         end if
         do p = 0, 16
            write(fmt, '("(es40.",i0,"e3)")') p
            write(buf, fmt) x
            read(buf, *, iostat=ios) back
            if (ios == 0 .and. back == x) exit
         end do
         buf = adjustl(buf)
         ex = index(buf, "E")
         s = buf(1:ex - 1)
         if (index(s, ".") > 0) then
            do while (s(len(s):len(s)) == "0")
               s = s(1:len(s) - 1)
            end do
            if (s(len(s):len(s)) == ".") s = s(1:len(s) - 1)
         end if
         read(buf(ex + 1:), *) p
         if (p /= 0) s = s//"e"//to_string(p)
         if (abs(x) >= 1.0e-4_dp .and. abs(x) < 1.0e15_dp) then
            do p = 0, 20
               write(fmt, '("(f0.",i0,")")') p
               write(buf, fmt) x
               read(buf, *, iostat=ios) back
               if (ios == 0 .and. back == x) exit
            end do
            buf = adjustl(buf)
            if (buf(1:1) == ".") buf = "0"//buf
            if (buf(1:2) == "-.") buf = "-0"//buf(2:)
            last = len_trim(buf)
            if (buf(last:last) == ".") last = last - 1
            if (last <= len(s)) s = buf(1:last)
         end if
      end function shortest_by_search
   end subroutine test_format_real_search

   !> parse_real (exact for up to 18 digits in extended precision, else strtod) against
   !> gfortran's own formatted READ, a conversion of its own (libgfortran): random decimals
   !> of 1 to 19 digits with the point anywhere or an exponent of -40 to 40 (inside and
   !> outside the exact path), 17-digit renderings of random doubles as a deck holds
   !> them, and decimals exactly halfway between two doubles, which round to the even one
   !> (9007199254740993 = 2**53 + 1 reads as 2**53).
   subroutine test_parse_real(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=40), allocatable :: texts(:)
      character(len=40) :: t
      character(len=19) :: digits
      real(dp) :: u, v, got, expected
      integer :: k, nd, j, point, e, nseed
      integer, allocatable :: seed(:)
      logical :: ok
      texts = [character(len=40) :: "9007199254740993", "9007199254740995", "-9007199254740993", &
         "18014398509481986", "0.5", "-0", "0.000", "1e-27", "999999999999999999e27", "123456789012345678e-27", &
         "4.9406564584124654e-324", "1.7976931348623157e308", "2.2250738585072014D-308", ".5", "5.", "+3.25e+02", &
         "4503599627370496.5", "4503599627370497.5", "-4503599627370497.5", "9007199254740991.5", &
         "9007199254740991.75", "2251799813685248.25", "2251799813685248.75"]
      call random_seed(size=nseed)
      allocate(seed(nseed))
      seed = 20261125
      call random_seed(put=seed)
      do k = 1, 40000
         call random_number(u)
         nd = 1 + int(u*19)
         do j = 1, nd
            call random_number(u)
            digits(j:j) = achar(iachar("0") + int(u*10))
         end do
         call random_number(u)
         point = int(u*(nd + 1))
         call random_number(v)
         if (mod(k, 2) == 0) then
            t = digits(1:point)//"."//digits(point + 1:nd)
         else
            e = -40 + int(v*81)
            t = digits(1:nd)//"e"//int_str(e)
         end if
         if (mod(k, 3) == 0) t = "-"//t
         if (t(1:1) == "." .and. len_trim(t) == 1) t = "0"
         texts = [texts, t]
      end do
      do k = 1, 20000
         call random_number(u)
         call random_number(v)
         write(t, "(es25.16e3)") (u - 0.5_dp)*10.0_dp**(int(v*12) - 3)
         texts = [texts, adjustl(t)]
      end do
      do k = 1, size(texts)
         call parse_real(trim(texts(k)), got, ok)
         read(texts(k), *) expected
         call check(error, ok .and. transfer(got, 1_8) == transfer(expected, 1_8), "parse_real('"// &
            trim(texts(k))//"') = "//format_real(got)//", READ gives "//format_real(expected))
         if (allocated(error)) return
      end do
   end subroutine test_parse_real

   !> The deck reader's eight-byte scans (femcod_bytes) against the byte-by-byte
   !> definitions written out here: the first control byte (below 32 but TAB, LF, FF, CR,
   !> or DEL) of random texts of every byte value, and the tokens (separated by bytes
   !> below 33 and commas), their first and last bytes and lines, and the line ends, of
   !> random texts of separators and token bytes (also above 127), over random spans
   !> whose lengths are not multiples of eight.
   subroutine test_word_scans(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: alphabet(12) = [9, 10, 12, 13, 32, 44, 48, 49, 46, 101, 45, 200]
      character(len=:), allocatable :: text
      integer, allocatable :: first(:), last(:), line(:), ref_first(:), ref_last(:), ref_line(:)
      real(dp) :: u, rate
      integer :: trial, n, i, i0, i1, expected, count, ends, nref, ln, k0, ln0
      logical :: inside
      if (.not. words_little_endian()) return
      do trial = 1, 3000
         call random_number(u)
         ! Every tenth text is long: many of the scans' blocks of 4 KiB, or of 127 words.
         if (mod(trial, 10) == 0) then
            n = 1 + int(u*20000)
         else
            n = 1 + int(u*70)
         end if
         ! Control bytes: 3 % of a short text's bytes, about two in a long one.
         rate = merge(0.03_dp, 2.0_dp/n, n <= 70)
         allocate(character(len=n) :: text)
         do i = 1, n
            call random_number(u)
            if (trial <= 1000) then
               ! Mostly ordinary text, a control byte now and then.
               if (u < 1 - rate) then
                  text(i:i) = achar(alphabet(1 + int(u/(1 - rate)*size(alphabet))))
               else
                  text(i:i) = achar(min(255, int((u - (1 - rate))/rate*256)))
               end if
            else
               text(i:i) = achar(alphabet(1 + int(u*size(alphabet))))
            end if
         end do
         if (trial <= 1000) then
            expected = huge(expected)
            do i = n, 1, -1
               if ((iachar(text(i:i)) < 32 .and. all(iachar(text(i:i)) /= [9, 10, 12, 13])) .or. &
                  iachar(text(i:i)) == 127) expected = i
            end do
            call check(error, first_control_byte(text), expected, "first control byte of a random text of "// &
               int_str(n)//" bytes")
            if (allocated(error)) return
            deallocate(text)
            cycle
         end if
         ! A span i0..i1 whose byte before is a separator (or the text's start).
         call random_number(u)
         i0 = 1 + int(u*n)
         if (i0 > 1) text(i0 - 1:i0 - 1) = " "
         call random_number(u)
         i1 = i0 + int(u*(n - i0 + 1))
         i1 = min(i1, n)
         allocate(ref_first(n), ref_last(n), ref_line(n))
         nref = 0
         ln = 0
         inside = .false.
         do i = i0, i1
            if (iachar(text(i:i)) < 33 .or. text(i:i) == ",") then
               if (inside) ref_last(nref) = i - 1
               inside = .false.
               if (text(i:i) == new_line("a")) ln = ln + 1
            else if (.not. inside) then
               inside = .true.
               nref = nref + 1
               ref_first(nref) = i
               ref_line(nref) = ln
            end if
         end do
         if (inside) ref_last(nref) = i1
         k0 = mod(trial, 5)
         ln0 = mod(trial, 7)
         call scan_tokens(text, i0, i1, k0, ln0, count, ends)
         call check(error, count == nref .and. ends == ln, "tokens and line ends of a span of "// &
            int_str(i1 - i0 + 1)//" bytes: "//int_str(count)//" and "//int_str(ends)//", expected "// &
            int_str(nref)//" and "//int_str(ln))
         if (allocated(error)) return
         call check(error, count_tokens(text, i0, i1), nref, "count_tokens of a span of "//int_str(i1 - i0 + 1)//" bytes")
         if (allocated(error)) return
         allocate(first(k0 + nref), last(k0 + nref), line(k0 + nref))
         call scan_tokens(text, i0, i1, k0, ln0, count, ends, first, last, line)
         call check(error, all(first(k0 + 1:) == ref_first(1:nref)) .and. all(last(k0 + 1:) == ref_last(1:nref)) &
            .and. all(line(k0 + 1:) == ln0 + ref_line(1:nref)), "token bounds and lines of a span of "// &
            int_str(i1 - i0 + 1)//" bytes")
         if (allocated(error)) return
         deallocate(text, first, last, line, ref_first, ref_last, ref_line)
      end do
   end subroutine test_word_scans

   !> femcod_bytes' eight_digits against Fortran's READ of the same eight characters, on
   !> 2000 random digit strings and the extremes; then each of the eight positions holding
   !> '/' or ':' (the bytes next to the digits), a blank or a byte above 127: refused.
   subroutine test_eight_digits(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=8) :: chunk
      character(len=*), parameter :: others = "/: "//achar(200)
      integer(8) :: value, expected
      real(dp) :: u
      integer :: trial, k, b
      logical :: ok
      if (.not. words_little_endian()) return
      do trial = 1, 2002
         if (trial == 1) then
            chunk = "00000000"
         else if (trial == 2) then
            chunk = "99999999"
         else
            do k = 1, 8
               call random_number(u)
               chunk(k:k) = achar(iachar("0") + int(u*10))
            end do
         end if
         read(chunk, "(i8)") expected
         call eight_digits(chunk, value, ok)
         call check(error, ok .and. value == expected, "eight_digits('"//chunk//"')")
         if (allocated(error)) return
         do k = 1, 8
            do b = 1, len(others)
               chunk = "12345678"
               chunk(k:k) = others(b:b)
               call eight_digits(chunk, value, ok)
               call check(error, .not. ok, "eight_digits refuses byte "//int_str(iachar(others(b:b)))// &
                  " at position "//int_str(k))
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_eight_digits

   !> int_str against the list-free i0 edit of Fortran's own formatted output, on the
   !> extremes of both kinds and on every power of ten and its neighbours.
   subroutine test_int_str(error)
      type(error_type), allocatable, intent(out) :: error
      integer(8), allocatable :: values(:)
      character(len=24) :: buf
      integer(8) :: p
      integer :: k
      values = [0_8, 1_8, -1_8, huge(1_8), -huge(1_8), -huge(1_8) - 1, int(huge(1), 8), -int(huge(1), 8) - 1]
      p = 1
      do k = 1, 18
         p = p*10
         values = [values, p - 1, p, p + 1, -(p - 1), -p, -(p + 1)]
      end do
      do k = 1, size(values)
         write(buf, '(i0)') values(k)
         call check(error, int_str(values(k)), trim(buf), "int_str(8-byte) of "//trim(buf))
         if (allocated(error)) return
         if (values(k) >= -int(huge(1), 8) - 1 .and. values(k) <= huge(1)) then
            call check(error, int_str(int(values(k))), trim(buf), "int_str of "//trim(buf))
            if (allocated(error)) return
         end if
      end do
   end subroutine test_int_str

   !> The heights are converted in parallel: with two bad values far apart (a name in
   !> the lower surface's last row, a NaN in its second) the error names the earlier
   !> one, as a reader going through the file would.
   subroutine test_first_bad_height(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path, text
      integer :: i, j, n
      n = 64
      text = "first bad"//nl//int_str(n)//" 1 10"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl
      do i = 1, 2*n
         do j = 1, n
            if (i == 2 .and. j == 7) then
               text = text//"NaN "
            else if (i == n .and. j == 3) then
               text = text//"x "
            else
               text = text//"0.5 "
            end if
         end do
         text = text//nl
      end do
      path = scratch_path("first_bad.deck")
      call write_text(path, text)
      call read_deck(path, deck, status)
      call check(error, status%code, 3, "a bad height is status 3")
      if (allocated(error)) return
      ! Line 7 of the file holds row 2 (line 6 holds row 1).
      call check(error, contains_text(status%message, path//":7:") .and. contains_text(status%message, &
         "row 2, column 7") .and. contains_text(status%message, "'NaN'"), "the NaN of row 2 is named: "//status%message)
   end subroutine test_first_bad_height

   !> The bad-deck cases, one test each: deck text, the line the error must name, and a
   !> word of what was expected.
   subroutine bad_case(k, name, text, where, expected)
      integer, intent(in) :: k
      character(len=:), allocatable, intent(out) :: name, text, where, expected
      select case (k)
      case (1)
         name = "missing value line 2"
         text = "x"//nl//"2 1.5"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":2:"
         expected = "NP PIXEL MAXCONT"
      case (2)
         name = "extra value line 3"
         text = "x"//nl//"2 1.5 3"//nl//"200 0.25 9"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl// heights
         where = ":3:"
         expected = "E1 NU1"
      case (3)
         name = "non-numeric height"
         text = header//"0 0.5"//nl//"1 abc"//nl//"2 2.5 3 3.5"//nl
         where = ":7:"
         expected = "lower-surface height"
      case (4)
         name = "NaN height"
         text = header//heights(1:len(heights) - 4)//"NaN"//nl
         where = ":8:"
         expected = "finite"
      case (5)
         name = "Inf height"
         text = header//"Inf 0.5"//nl//"1 1.5"//nl//"2 2.5 3 3.5"//nl
         where = ":6:"
         expected = "finite"
      case (6)
         name = "overflowing height"
         text = header//"0 0.5"//nl//"1 1.5"//nl//"2 1e999 3 3.5"//nl
         where = ":8:"
         expected = "finite"
      case (7)
         name = "NP zero"
         text = "x"//nl//"0 1.5 3"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":2:"
         expected = "NP"
      case (8)
         name = "NP negative"
         text = "x"//nl//"-2 1.5 3"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":2:"
         expected = "NP"
      case (9)
         name = "NP not an integer"
         text = "x"//nl//"2.5 1.5 3"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl// heights
         where = ":2:"
         expected = "NP"
      case (10)
         name = "NP overflowing"
         text = "x"//nl//"99999999999 1.5 3"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl// heights
         where = ":2:"
         expected = "NP"
      case (11)
         name = "PIXEL zero"
         text = "x"//nl//"2 0 3"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":2:"
         expected = "PIXEL"
      case (12)
         name = "PIXEL negative"
         text = "x"//nl//"2 -1 3"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":2:"
         expected = "PIXEL"
      case (13)
         name = "MAXCONT zero"
         text = "x"//nl//"2 1.5 0"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":2:"
         expected = "MAXCONT"
      case (14)
         name = "MAXCONT above NP**2"
         text = "x"//nl//"2 1.5 5"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl// heights
         where = ":2:"
         expected = "MAXCONT"
      case (15)
         name = "E zero"
         text = "x"//nl//"2 1.5 3"//nl//"0 0.25"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":3:"
         expected = "E1"
      case (16)
         name = "E negative"
         text = "x"//nl//"2 1.5 3"//nl//"200 0.25"//nl//"-2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":4:"
         expected = "E2"
      case (17)
         name = "nu = 0.5"
         text = "x"//nl//"2 1.5 3"//nl//"200 0.5"//nl//"2e7 0.25"//nl//"2e7 0.3"//nl//heights
         where = ":3:"
         expected = "NU1"
      case (18)
         name = "nu = -1"
         text = "x"//nl//"2 1.5 3"//nl//"200 0.25"//nl//"2e7 0.25"//nl//"2e7 -1"//nl//heights
         where = ":5:"
         expected = "NU3"
      case (19)
         name = "truncated heights"
         text = header//"0 0.5"//nl//"1 1.5"//nl//"2 2.5 3"//nl
         where = ":8:"
         expected = "heights"
      case (20)
         name = "trailing values"
         text = header//heights//"4"//nl
         where = ":9:"
         expected = "end of the deck"
      case (21)
         name = "binary content"
         text = header//"0 0.5"//nl//achar(0)//achar(1)//"1 1.5"//nl//"2 2.5 3 3.5"//nl
         where = ":7:"
         expected = "binary"
      case (22)
         name = "header cut short"
         text = "x"//nl//"2 1.5 3"//nl//"200 0.25"
         where = ":4:"
         expected = "E2 NU2"
      end select
   end subroutine bad_case

   subroutine run_bad(error, k)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: k
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path, name, text, where, expected
      call bad_case(k, name, text, where, expected)
      path = scratch_path("bad.deck")
      call write_text(path, text)
      call read_deck(path, deck, status)
      call check(error, status%code, 3, name//": bad input is status 3")
      if (allocated(error)) return
      call check(error, contains_text(status%message, path//where), &
         name//": message names file and line "//where//": "//status%message)
      if (allocated(error)) return
      call check(error, contains_text(status%message, expected) .and. contains_text(status%message, "found"), &
         name//": message says what was expected and found: "//status%message)
   end subroutine run_bad

   subroutine bad_01(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 1)
   end subroutine bad_01
   subroutine bad_02(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 2)
   end subroutine bad_02
   subroutine bad_03(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 3)
   end subroutine bad_03
   subroutine bad_04(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 4)
   end subroutine bad_04
   subroutine bad_05(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 5)
   end subroutine bad_05
   subroutine bad_06(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 6)
   end subroutine bad_06
   subroutine bad_07(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 7)
   end subroutine bad_07
   subroutine bad_08(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 8)
   end subroutine bad_08
   subroutine bad_09(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 9)
   end subroutine bad_09
   subroutine bad_10(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 10)
   end subroutine bad_10
   subroutine bad_11(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 11)
   end subroutine bad_11
   subroutine bad_12(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 12)
   end subroutine bad_12
   subroutine bad_13(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 13)
   end subroutine bad_13
   subroutine bad_14(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 14)
   end subroutine bad_14
   subroutine bad_15(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 15)
   end subroutine bad_15
   subroutine bad_16(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 16)
   end subroutine bad_16
   subroutine bad_17(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 17)
   end subroutine bad_17
   subroutine bad_18(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 18)
   end subroutine bad_18
   subroutine bad_19(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 19)
   end subroutine bad_19
   subroutine bad_20(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 20)
   end subroutine bad_20
   subroutine bad_21(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 21)
   end subroutine bad_21
   subroutine bad_22(error)
      type(error_type), allocatable, intent(out) :: error
      call run_bad(error, 22)
   end subroutine bad_22

   subroutine test_bad_files(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      call read_deck(scratch_path("no-such.deck"), deck, status)
      call check(error, status%code == 3 .and. contains_text(status%message, "no such file"), &
         "missing file: "//status%message)
      if (allocated(error)) return
      status%code = 0
      call read_deck(scratch_path(""), deck, status)
      call check(error, status%code == 3 .and. contains_text(status%message, "directory"), &
         "directory: "//status%message)
      if (allocated(error)) return
      status%code = 0
      call write_text(scratch_path("empty.deck"), "")
      call read_deck(scratch_path("empty.deck"), deck, status)
      call check(error, status%code == 3 .and. contains_text(status%message, ":1:"), "empty file: "//status%message)
   end subroutine test_bad_files

   !> Text is indexed by default integers, so a deck of 2^31 - 2^16 + 2 bytes (a sparse
   !> file: one byte written at that position) is refused with its size, before any of it
   !> is read; the limit named is 2^31 - 2^16 bytes.
   subroutine test_huge_deck(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path
      integer(8) :: bytes
      integer :: unit
      bytes = 2_8**31 - 2_8**16 + 2
      path = scratch_path("huge.deck")
      open(newunit=unit, file=path, access="stream", form="unformatted", status="replace", action="write")
      write(unit, pos=bytes) "x"
      close(unit)
      call read_deck(path, deck, status)
      open(newunit=unit, file=path, status="old")
      close(unit, status="delete")
      call check(error, status%code == 3 .and. contains_text(status%message, "found "//int_str(bytes)//" bytes") &
         .and. contains_text(status%message, "at most "//int_str(2_8**31 - 2_8**16)//" bytes"), &
         "a deck of "//int_str(bytes)//" bytes: "//status%message)
   end subroutine test_huge_deck

   !> write_deck stops at its byte limit (MAX_TEXT_BYTES, 2 GiB less 64 KiB, in use; a
   !> smaller one here): a limit of the deck's own size writes it, one byte less refuses
   !> it with exit code 2 and leaves no file. The size is the file's, measured here.
   subroutine test_deck_limit(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path
      integer(8) :: bytes
      integer :: unit
      path = scratch_path("limit.deck")
      call write_text(path, header//heights)
      call read_deck(path, deck, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call write_deck(path, deck, status)
      inquire(file=path, size=bytes)
      call write_deck(path, deck, status, max_bytes=int(bytes))
      call check(error, status%code, 0, "a limit of the deck's size ("//int_str(bytes)//" bytes) writes it")
      if (allocated(error)) return
      open(newunit=unit, file=path, status="old")
      close(unit, status="delete")
      call write_deck(path, deck, status, max_bytes=int(bytes) - 1)
      call check(error, status%code == 2 .and. contains_text(status%message, "more than "//int_str(bytes - 1)// &
         " bytes") .and. .not. file_exists(path), "one byte less refuses it and writes nothing: "//status%message)
   end subroutine test_deck_limit

   subroutine test_run_bad_deck(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: path, prefix
      integer :: code
      path = scratch_path("run-bad.deck")
      prefix = scratch_path("run-bad-out")
      call write_text(path, header//"0 0.5"//nl//"1 abc"//nl//"2 2.5 3 3.5"//nl)
      call run_femcod([string_type("run"), string_type(path), string_type("-o"), string_type(prefix), &
         string_type("--quiet")], code)
      call check(error, code, 3, "femcod run on a bad deck exits with 3")
      if (allocated(error)) return
      call check(error, .not. (file_exists(prefix//".history.csv") .or. file_exists(prefix//".loads.csv") .or. &
         file_exists(prefix//".contacts.csv")), "no result file is written")
   end subroutine test_run_bad_deck

   !> Editors on some systems start a UTF-8 file with the bytes EF BB BF: the deck reads,
   !> and its label is the text after them.
   subroutine test_bom(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=*), parameter :: nl = new_line("a")
      call write_text(scratch_path("bom.deck"), achar(239)//achar(187)//achar(191)//"with a BOM"//nl//"1 1 1"//nl// &
         "200 0.25"//nl//"200 0.25"//nl//"200 0.25"//nl//"0"//nl//"0"//nl)
      call read_deck(scratch_path("bom.deck"), deck, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, deck%label, "with a BOM")
   end subroutine test_bom
   !> The streamed reader (femcod_deck_stream: femcod-mpi's rank 0 reads a text deck in
   !> slabs) read in chunks of 1, 13 and 4096 bytes and the default, and in slabs of 7
   !> values, so that tokens, CR LF pairs and lines are cut at every place:
   !> - a 40 x 40 deck of random values between random separators (blanks, tabs, commas,
   !>   LF, CR LF) gives exactly the values Fortran's READ gives the same strings, and its
   !>   header as written;
   !> - the input/ decks give what read_deck gives, bit for bit;
   !> - each of bad_case's 22 decks is refused as read_deck is: status 3, the message
   !>   naming the file and the line bad_case states, what was expected and what found.
   subroutine test_stream(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 40, chunks(4) = [1, 13, 4096, 0]
      character(len=*), parameter :: separators(5) = [character(len=2) :: " ", achar(9), ",", nl, achar(13)//nl]
      character(len=*), parameter :: decks(3) = [character(len=32) :: "input/sphere_d1.deck", &
         "input/rough_selfaffine_32.deck", "input/square_punch_n27.deck"]
      type(contact_problem) :: deck, whole
      type(status_type) :: status
      character(len=:), allocatable :: path, text, name, where, expected
      character(len=25) :: t
      real(dp), allocatable :: values(:), got(:)
      real(dp) :: u
      integer :: k, c, sep, d
      path = scratch_path("stream.deck")
      allocate(values(2*np*np))
      text = "streamed"//nl//"40 2.5 100"//nl//"200 0.3"//nl//"150 0.25"//nl//"1e7 0.25"//nl
      do k = 1, size(values)
         call random_number(u)
         write(t, "(es25.16e3)") (u - 0.5_dp)*10.0_dp**(mod(k, 9) - 4)
         read(t, *) values(k)
         call random_number(u)
         sep = 1 + int(u*size(separators))
         text = text//trim(adjustl(t))//trim(separators(sep))
         if (sep == 1 .or. sep == 2) text = text//" "
      end do
      call write_text(path, text)
      do c = 1, size(chunks)
         call stream_all(path, chunks(c), deck, got, status)
         call check(error, status%code, 0, "chunks of "//to_string(chunks(c))//": "//status%message)
         if (allocated(error)) return
         call check(error, deck%np == np .and. deck%pixel == 2.5_dp .and. deck%maxcont == 100 .and. &
            deck%young(2) == 150 .and. deck%poisson(3) == 0.25_dp .and. deck%label == "streamed", "the header")
         if (allocated(error)) return
         call check(error, all(got == values), "chunks of "//to_string(chunks(c))//": heights differ from READ's")
         if (allocated(error)) return
      end do
      do d = 1, size(decks)
         call read_deck(trim(decks(d)), whole, status)
         do c = 1, size(chunks)
            call stream_all(trim(decks(d)), chunks(c), deck, got, status)
            call check(error, status%code, 0, trim(decks(d))//": "//status%message)
            if (allocated(error)) return
            call check(error, all(got == [reshape(transpose(whole%lower), [whole%np**2]), &
               reshape(transpose(whole%upper), [whole%np**2])]), trim(decks(d))//": not read_deck's heights")
            if (allocated(error)) return
         end do
      end do
      do k = 1, 22
         call bad_case(k, name, text, where, expected)
         call write_text(path, text)
         do c = 1, size(chunks)
            call stream_all(path, chunks(c), deck, got, status)
            call check(error, status%code, 3, name//", chunks of "//to_string(chunks(c))//": status "// &
               to_string(status%code)//" "//status%message)
            if (allocated(error)) return
            call check(error, contains_text(status%message, path//where) .and. contains_text(status%message, &
               expected) .and. contains_text(status%message, "found"), name//", chunks of "//to_string(chunks(c))// &
               ": the message "//status%message//" should name "//where//" and "//expected)
            if (allocated(error)) return
         end do
      end do
   contains
      !> The header, and all 2 NP^2 heights in slabs of 7 values (file order).
      subroutine stream_all(file, chunk, header, heights, st)
         character(len=*), intent(in) :: file
         integer, intent(in) :: chunk
         type(contact_problem), intent(out) :: header
         real(dp), allocatable, intent(out) :: heights(:)
         type(status_type), intent(out) :: st
         type(deck_stream) :: stream
         integer :: at, n
         allocate(heights(0))
         if (chunk > 0) then
            call open_deck_stream(file, stream, header, st, chunk_bytes=chunk)
         else
            call open_deck_stream(file, stream, header, st)
         end if
         if (st%code /= 0) return
         deallocate(heights)
         allocate(heights(2*header%np**2))
         at = 0
         do while (at < size(heights))
            n = min(7, size(heights) - at)
            call read_deck_heights(stream, heights(at + 1:at + n), st)
            if (st%code /= 0) exit
            at = at + n
         end do
         call close_deck_stream(stream)
      end subroutine stream_all
   end subroutine test_stream

   !> balanced_cuts, by hand: four equal blocks in two parts are 2 + 2; a heavy first
   !> block (3, 1, 1, 1: middles 1.5, 3.5, 4.5, 5.5 of 6, halves at 3) stands alone; no
   !> weight at all goes to the first part; one block in three parts goes to the part its
   !> middle falls in (the second). And on 200 random weights in 1 to 9 parts: the cuts
   !> rise, end at the last block, and no part is heavier than its share plus one block.
   subroutine test_balanced_cuts(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: w(200), load
      integer :: parts, r
      integer, allocatable :: cuts(:)
      call check(error, all(balanced_cuts([1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp], 2) == [0, 2, 4]), "1, 1, 1, 1 in 2")
      if (allocated(error)) return
      call check(error, all(balanced_cuts([3.0_dp, 1.0_dp, 1.0_dp, 1.0_dp], 2) == [0, 1, 4]), "3, 1, 1, 1 in 2")
      if (allocated(error)) return
      call check(error, all(balanced_cuts([0.0_dp, 0.0_dp], 3) == [0, 2, 2, 2]), "no weight in 3")
      if (allocated(error)) return
      call check(error, all(balanced_cuts([1.0_dp], 3) == [0, 0, 1, 1]), "one block in 3")
      if (allocated(error)) return
      call random_number(w)
      do parts = 1, 9
         allocate(cuts(0:parts))
         cuts(:) = balanced_cuts(w, parts)
         call check(error, cuts(0) == 0 .and. cuts(parts) == size(w) .and. all(cuts(1:) >= cuts(:parts - 1)), &
            to_string(parts)//" parts: the cuts do not rise to the last block")
         if (allocated(error)) return
         do r = 1, parts
            load = sum(w(cuts(r - 1) + 1:cuts(r)))
            call check(error, load <= sum(w)/parts + maxval(w), to_string(parts)//" parts: part "//to_string(r)// &
               " carries "//to_string(load)//" of "//to_string(sum(w)))
            if (allocated(error)) return
         end do
         deallocate(cuts)
      end do
   end subroutine test_balanced_cuts

   !> femcod-mpi's ranks each read one range of a text deck's bytes (cut at a separator
   !> at or after an even share), counting its heights and lines first so that each range
   !> knows its first height's number and line: read range after range in 1 to 7 pieces,
   !> the heights are read_deck's; the counts, read in chunks of 1, 7 and 4096 bytes
   !> (tokens and lines cut anywhere), are the whole file's; a fault in the heights gets
   !> read_deck's own message for the whole file, word for word; every range's file is
   !> closed after it (NEWUNIT numbers are negative: a check for a unit >= 0 never closed
   !> one).
   subroutine test_ranges(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: pieces(5) = [1, 2, 3, 5, 7]
      character(len=*), parameter :: decks(3) = [character(len=32) :: "input/sphere_d1.deck", &
         "input/rough_selfaffine_32.deck", "input/square_punch_n27.deck"]
      type(contact_problem) :: whole
      type(status_type) :: status, whole_status
      character(len=:), allocatable :: path, text, name, where, expected
      real(dp), allocatable :: got(:)
      integer :: d, p, k, at
      do d = 1, size(decks)
         call read_deck(trim(decks(d)), whole, status)
         call check(error, counts_in_chunks(trim(decks(d))), trim(decks(d))//": the counts depend on the chunks")
         if (allocated(error)) return
         do p = 1, size(pieces)
            call read_ranges(trim(decks(d)), pieces(p), got, status)
            call check(error, status%code, 0, trim(decks(d))//": "//status%message)
            if (allocated(error)) return
            call check(error, all(got == [reshape(transpose(whole%lower), [whole%np**2]), &
               reshape(transpose(whole%upper), [whole%np**2])]), trim(decks(d))//" in "//to_string(pieces(p))// &
               " ranges: not read_deck's heights")
            if (allocated(error)) return
         end do
      end do
      path = scratch_path("ranges.deck")
      ! The faults in the heights (a bad height, too many, a binary byte; and a binary
      ! byte after a bad height, which read_deck tells first), each with read_deck's own
      ! message; those of the header are rank 0's alone, and too few heights are told
      ! from the counts (femcod-mpi's test_command.sh has both).
      do k = 1, 23
         if (all(k /= [3, 4, 5, 6, 20, 21, 23])) cycle
         if (k <= 22) then
            call bad_case(k, name, text, where, expected)
         else
            name = "a binary byte after a bad height"
            text = read_text("input/sphere_d1.deck")
            at = index(text, nl//"0 ")
            text = text(1:at)//"x1"//text(at + 2:len(text)/2)//achar(1)//text(len(text)/2 + 1:)
         end if
         call write_text(path, text)
         whole_status = status_type()
         call read_deck(path, whole, whole_status)
         do p = 1, size(pieces)
            call read_ranges(path, pieces(p), got, status)
            call check(error, status%code == 3 .and. status%message == whole_status%message, name//" in "// &
               to_string(pieces(p))//" ranges: "//status%message//", but read_deck: "//whole_status%message)
            if (allocated(error)) return
         end do
      end do
   contains
      !> The heights of `file` read range after range, its bytes cut in n ranges; the
      !> first range's fault, as femcod-mpi's first failing rank.
      subroutine read_ranges(file, n, heights, st)
         character(len=*), intent(in) :: file
         integer, intent(in) :: n
         real(dp), allocatable, intent(out) :: heights(:)
         type(status_type), intent(out) :: st
         type(contact_problem) :: header
         type(deck_stream) :: stream
         integer(i8) :: bounds(0:n), tokens(n), lines(n), binary(3, n), first_byte, size, before, line, total
         integer :: r, unit
         logical :: open
         allocate(heights(0))
         call open_deck_stream(file, stream, header, st)
         first_byte = stream%next
         size = stream%size
         line = stream%line0
         call close_deck_stream(stream)
         if (st%code /= 0) return
         bounds(0) = first_byte
         bounds(n) = size + 1
         do r = 1, n - 1
            call separator_at_or_after(file, first_byte + ((size - first_byte + 1)*r)/n, size, bounds(r), st)
         end do
         do r = 1, n
            call count_deck_range(file, bounds(r - 1), bounds(r) - 1, tokens(r), lines(r), binary(:, r), st)
         end do
         ! A binary byte anywhere is told first, on its line (femcod-mpi: after the counts).
         line = stream%line0
         do r = 1, n
            if (binary(1, r) > 0) then
               call set_error(st, 3, binary_byte(file, int(line + binary(2, r)), int(binary(3, r)), binary(1, r)))
               return
            end if
            line = line + lines(r)
         end do
         line = stream%line0
         total = 2*int(header%np, i8)**2
         deallocate(heights)
         allocate(heights(total))
         before = 0
         do r = 1, n
            if (st%code /= 0) return
            if (before <= total) then
               call open_deck_range(file, header%np, bounds(r - 1), bounds(r) - 1, int(line), before, stream, st)
               unit = stream%unit
               if (st%code == 0) call read_deck_heights(stream, heights(before + 1:min(total, before + tokens(r))), st)
               call close_deck_stream(stream)
               inquire(unit=unit, opened=open)
               if (open) call set_bad(st, "the range's file is still open after close_deck_stream")
            end if
            before = before + tokens(r)
            line = line + lines(r)
         end do
      end subroutine read_ranges
      !> Whether the heights' counts (tokens, line ends) of `file` are the same read in
      !> chunks of 1, 7 and 4096 bytes as in one, and the tokens 2 NP^2.
      logical function counts_in_chunks(file) result(same)
         character(len=*), intent(in) :: file
         integer, parameter :: chunks(3) = [1, 7, 4096]
         type(contact_problem) :: header
         type(deck_stream) :: stream
         type(status_type) :: st
         integer(i8) :: first_byte, last, one(2), other(2), binary(3)
         integer :: c
         call open_deck_stream(file, stream, header, st)
         first_byte = stream%next
         last = stream%size
         call close_deck_stream(stream)
         call count_deck_range(file, first_byte, last, one(1), one(2), binary, st)
         same = st%code == 0 .and. one(1) == 2*int(header%np, i8)**2
         do c = 1, size(chunks)
            call count_deck_range(file, first_byte, last, other(1), other(2), binary, st, at_a_time=chunks(c))
            same = same .and. st%code == 0 .and. all(other == one)
         end do
      end function counts_in_chunks
      subroutine set_bad(st, message)
         type(status_type), intent(inout) :: st
         character(len=*), intent(in) :: message
         st%code = 99
         st%message = message
      end subroutine set_bad
   end subroutine test_ranges
end module test_deck
