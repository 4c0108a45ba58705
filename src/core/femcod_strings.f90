!> Strings: a string type, lists of strings, text building, lines, and the escapes of XML
!> and JSON (no I/O). The numbers' text (femcod_decimal) is re-exported from here.
module femcod_strings
   use femcod_kinds, only: dp, i8
   use femcod_decimal, only: int_str, integer_text, real_str, fixed_str, format_real, format_reals, parse_real, &
      parse_integer, is_digit, json_number, sig_str, without_trailing_zeros
   implicit none
   private
   public :: count_text, ends_with
   public :: string_type, int_str, real_str, fixed_str, split_list, text_builder, add_line, add_lines, add_text, built_text
   public :: without_trailing_zeros, xml_escape, json_string, json_number, sig_str, next_line
   public :: parse_real, parse_integer, parse_real_list, parse_integer_list, format_real, format_reals, is_digit, &
      append_string, integer_text, lower_case

   !> A string of any length, for lists of arguments.
   type :: string_type
      character(len=:), allocatable :: s
   end type string_type

   !> A growing text (a CSV file being built): lines are appended in amortised O(length),
   !> where repeated concatenation would copy the whole text every time.
   type :: text_builder
      character(len=:), allocatable :: buffer
      integer :: length = 0
   end type text_builder

contains

   !> Append `text` as it is (no line end).
   pure subroutine add_text(builder, text)
      type(text_builder), intent(inout) :: builder
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: bigger
      integer :: need
      need = builder%length + len(text)
      if (.not. allocated(builder%buffer)) allocate(character(len=max(4096_i8, 2*int(need, i8))) :: builder%buffer)
      if (need > len(builder%buffer)) then
         ! Doubled in 64 bits and capped: 2 * need leaves a default integer above 1 GiB
         ! (the text itself stays below 2 GiB: write_deck refuses more).
         allocate(character(len=min(2*int(need, i8), int(huge(need), i8))) :: bigger)
         bigger(1:builder%length) = builder%buffer(1:builder%length)
         call move_alloc(bigger, builder%buffer)
      end if
      builder%buffer(builder%length + 1:need) = text
      builder%length = need
   end subroutine add_text

   !> Append `line` and a line end.
   pure subroutine add_line(builder, line)
      type(text_builder), intent(inout) :: builder
      character(len=*), intent(in) :: line
      call add_text(builder, line//new_line("a"))
   end subroutine add_line

   !> Append up to sixteen lines (the items of a `write(unit, '(a)') a, b, ...`).
   pure subroutine add_lines(builder, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15, l16)
      type(text_builder), intent(inout) :: builder
      character(len=*), intent(in) :: l1
      character(len=*), intent(in), optional :: l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15, l16
      call add_line(builder, l1)
      if (present(l2)) call add_line(builder, l2)
      if (present(l3)) call add_line(builder, l3)
      if (present(l4)) call add_line(builder, l4)
      if (present(l5)) call add_line(builder, l5)
      if (present(l6)) call add_line(builder, l6)
      if (present(l7)) call add_line(builder, l7)
      if (present(l8)) call add_line(builder, l8)
      if (present(l9)) call add_line(builder, l9)
      if (present(l10)) call add_line(builder, l10)
      if (present(l11)) call add_line(builder, l11)
      if (present(l12)) call add_line(builder, l12)
      if (present(l13)) call add_line(builder, l13)
      if (present(l14)) call add_line(builder, l14)
      if (present(l15)) call add_line(builder, l15)
      if (present(l16)) call add_line(builder, l16)
   end subroutine add_lines

   !> The text built so far.
   pure function built_text(builder) result(text)
      type(text_builder), intent(in) :: builder
      character(len=:), allocatable :: text
      if (builder%length == 0) then
         text = ""
      else
         text = builder%buffer(1:builder%length)
      end if
   end function built_text

   !> An integer without blanks.
   !> "1 value", "2 values": a count with its noun, plural where the count is not 1.
   pure function count_text(n, noun) result(text)
      integer, intent(in) :: n
      character(len=*), intent(in) :: noun
      character(len=:), allocatable :: text
      text = int_str(n)//" "//noun
      if (n /= 1) text = text//"s"
   end function count_text

   !> Split "a,b,c" at commas.
   function split_list(text) result(parts)
      character(len=*), intent(in) :: text
      type(string_type), allocatable :: parts(:)
      integer :: n, start, k
      n = 1
      do k = 1, len(text)
         if (text(k:k) == ",") n = n + 1
      end do
      allocate(parts(n))
      n = 0
      start = 1
      do k = 1, len(text) + 1
         if (k > len(text)) then
            n = n + 1
            parts(n)%s = text(start:k - 1)
         else if (text(k:k) == ",") then
            n = n + 1
            parts(n)%s = text(start:k - 1)
            start = k + 1
         end if
      end do
   end function split_list

   !> Parse a comma-separated list of numbers (command-line options such as --loads);
   !> `ok` is false when an item is not a number.
   subroutine parse_real_list(text, values, ok)
      character(len=*), intent(in) :: text
      real(dp), allocatable, intent(out) :: values(:)
      logical, intent(out) :: ok
      type(string_type), allocatable :: parts(:)
      integer :: k
      parts = split_list(text)
      allocate(values(size(parts)))
      ok = size(parts) > 0
      do k = 1, size(parts)
         call parse_real(parts(k)%s, values(k), ok)
         if (.not. ok) return
      end do
   end subroutine parse_real_list

   !> Parse a comma-separated list of integers; `ok` is false when an item is not one.
   subroutine parse_integer_list(text, values, ok)
      character(len=*), intent(in) :: text
      integer, allocatable, intent(out) :: values(:)
      logical, intent(out) :: ok
      type(string_type), allocatable :: parts(:)
      integer :: k
      parts = split_list(text)
      allocate(values(size(parts)))
      ok = size(parts) > 0
      do k = 1, size(parts)
         call parse_integer(parts(k)%s, values(k), ok)
         if (.not. ok) return
      end do
   end subroutine parse_integer_list

   !> Append `text` to a list of strings (the elements are moved, not copied; gfortran 12
   !> mishandles [list, string_type(text)] for some selectors).
   pure subroutine append_string(list, text)
      type(string_type), allocatable, intent(inout) :: list(:)
      character(len=*), intent(in) :: text
      type(string_type), allocatable :: longer(:)
      integer :: k
      if (.not. allocated(list)) allocate(list(0))
      allocate(longer(size(list) + 1))
      do k = 1, size(list)
         call move_alloc(list(k)%s, longer(k)%s)
      end do
      longer(size(list) + 1)%s = text
      call move_alloc(longer, list)
   end subroutine append_string

   !> `s` with the ASCII capitals made small (keys of file headers are compared so).
   pure function lower_case(s) result(t)
      character(len=*), intent(in) :: s
      character(len=len(s)) :: t
      integer :: k
      t = s
      do k = 1, len(s)
         if (s(k:k) >= "A" .and. s(k:k) <= "Z") t(k:k) = achar(iachar(s(k:k)) + 32)
      end do
   end function lower_case

   !> Text for XML content and attribute values: & < > " ' as entities.
   !> True when `text` ends with `tail`.
   pure logical function ends_with(text, tail)
      character(len=*), intent(in) :: text, tail
      ends_with = .false.
      if (len(text) >= len(tail)) ends_with = text(len(text) - len(tail) + 1:) == tail
   end function ends_with

   pure function xml_escape(s) result(e)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: e
      integer :: k
      e = ""
      do k = 1, len(s)
         select case (s(k:k))
         case ("&")
            e = e//"&amp;"
         case ("<")
            e = e//"&lt;"
         case (">")
            e = e//"&gt;"
         case ('"')
            e = e//"&quot;"
         case ("'")
            e = e//"&apos;"
         case default
            e = e//s(k:k)
         end select
      end do
   end function xml_escape

   !> A JSON string literal (RFC 8259): quotes, backslashes and control characters
   !> escaped; other bytes (UTF-8) as they are.
   pure function json_string(s) result(j)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: j
      character(len=*), parameter :: hex = "0123456789abcdef"
      integer :: k, c
      j = '"'
      do k = 1, len(s)
         c = iachar(s(k:k))
         select case (c)
         case (34)
            j = j//'\"'
         case (92)
            j = j//'\\'
         case (10)
            j = j//'\n'
         case (9)
            j = j//'\t'
         case (13)
            j = j//'\r'
         case (0:8, 11:12, 14:31)
            j = j//'\u00'//hex(c/16 + 1:c/16 + 1)//hex(mod(c, 16) + 1:mod(c, 16) + 1)
         case default
            j = j//s(k:k)
         end select
      end do
      j = j//'"'
   end function json_string

   !> The next line of `text` from position `a` (CR LF or LF ends); false at the end.
   logical function next_line(text, a, line)
      character(len=*), intent(in) :: text
      integer, intent(inout) :: a
      character(len=:), allocatable, intent(out) :: line
      integer :: b
      next_line = a <= len(text)
      if (.not. next_line) return
      b = index(text(a:), achar(10))
      if (b == 0) then
         line = text(a:)
         a = len(text) + 1
      else
         line = text(a:a + b - 2)
         a = a + b
      end if
      if (len(line) > 0) then
         if (line(len(line):len(line)) == achar(13)) line = line(1:len(line) - 1)
      end if
   end function next_line
end module femcod_strings
