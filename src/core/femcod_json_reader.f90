!> A reader of JSON text (RFC 8259) into its leaves: every number, string, true, false
!> and null with the path that leads to it, "scene.NP" or "loads[0].load_nN" (arrays
!> counted from 0, as JavaScript and Python count). It reads what femcod's own writers
!> wrote (PREFIX.summary.json and the studies' JSON) for `femcod report`, and rejects
!> anything else with the line and what was expected.
module femcod_json_reader
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_strings, only: int_str
   implicit none
   private
   public :: json_leaf, read_json_leaves, leaf_index, leaf_text, leaf_real, leaf_count
   public :: JSON_NUMBER, JSON_STRING, JSON_BOOLEAN, JSON_NULL

   integer, parameter :: JSON_NUMBER = 1, JSON_STRING = 2, JSON_BOOLEAN = 3, JSON_NULL = 4

   !> One leaf: its path, its text (a number as written, a string unescaped, "true",
   !> "false" or "null") and its kind (JSON_NUMBER, ...).
   type :: json_leaf
      character(len=:), allocatable :: path, text
      integer :: kind = JSON_NULL
   end type json_leaf

   !> The text being read, the byte reached and its line (for messages).
   type :: json_cursor
      character(len=:), allocatable :: source
      integer :: pos = 1, line = 1, count = 0
      type(json_leaf), allocatable :: leaves(:)
   end type json_cursor

   !> Nesting deeper than this is refused (femcod writes four levels).
   integer, parameter :: MAX_DEPTH = 64

contains

   !> The leaves of the JSON `text`, in document order. `source` names the file in an
   !> error (STATUS_BAD_INPUT, "source:line: expected ...").
   subroutine read_json_leaves(text, source, leaves, status)
      character(len=*), intent(in) :: text, source
      type(json_leaf), allocatable, intent(out) :: leaves(:)
      type(status_type), intent(inout) :: status
      type(json_cursor) :: c
      character(len=:), allocatable :: message
      c%source = text
      allocate(c%leaves(64))
      message = ""
      call parse_value(c, "", 0, message)
      if (message == "") then
         call skip_blanks(c)
         if (c%pos <= len(c%source)) message = "expected the end of the text after the top value"
      end if
      if (message /= "") then
         call set_error(status, STATUS_BAD_INPUT, source//":"//int_str(c%line)//": "//message)
         allocate(leaves(0))
         return
      end if
      leaves = c%leaves(1:c%count)
   end subroutine read_json_leaves

   !> One value at `path`; `message` is set on the first error.
   recursive subroutine parse_value(c, path, depth, message)
      type(json_cursor), intent(inout) :: c
      character(len=*), intent(in) :: path
      integer, intent(in) :: depth
      character(len=:), allocatable, intent(inout) :: message
      character(len=:), allocatable :: key, s
      integer :: n
      if (depth > MAX_DEPTH) then
         message = "nesting deeper than "//int_str(MAX_DEPTH)//" levels"
         return
      end if
      call skip_blanks(c)
      if (c%pos > len(c%source)) then
         message = "expected a value, found the end of the text"
         return
      end if
      select case (c%source(c%pos:c%pos))
      case ("{")
         c%pos = c%pos + 1
         call skip_blanks(c)
         if (next_is(c, "}")) return
         do
            call skip_blanks(c)
            call parse_string(c, key, message)
            if (message /= "") return
            call skip_blanks(c)
            if (.not. next_is(c, ":")) then
               message = "expected ':' after the key """//key//""""
               return
            end if
            call parse_value(c, joined(path, key), depth + 1, message)
            if (message /= "") return
            call skip_blanks(c)
            if (next_is(c, "}")) return
            if (.not. next_is(c, ",")) then
               message = "expected ',' or '}' in an object"
               return
            end if
         end do
      case ("[")
         c%pos = c%pos + 1
         call skip_blanks(c)
         if (next_is(c, "]")) return
         n = 0
         do
            call parse_value(c, path//"["//int_str(n)//"]", depth + 1, message)
            if (message /= "") return
            n = n + 1
            call skip_blanks(c)
            if (next_is(c, "]")) return
            if (.not. next_is(c, ",")) then
               message = "expected ',' or ']' in an array"
               return
            end if
         end do
      case ('"')
         call parse_string(c, s, message)
         if (message == "") call add_leaf(c, path, s, JSON_STRING)
      case ("t")
         call parse_word(c, path, "true", JSON_BOOLEAN, message)
      case ("f")
         call parse_word(c, path, "false", JSON_BOOLEAN, message)
      case ("n")
         call parse_word(c, path, "null", JSON_NULL, message)
      case default
         call parse_number(c, path, message)
      end select
   end subroutine parse_value

   !> "a.b": a key below a path ("" at the top).
   pure function joined(path, key) result(p)
      character(len=*), intent(in) :: path, key
      character(len=:), allocatable :: p
      if (path == "") then
         p = key
      else
         p = path//"."//key
      end if
   end function joined

   !> True, and past it, when the next byte is `ch`.
   logical function next_is(c, ch)
      type(json_cursor), intent(inout) :: c
      character(len=1), intent(in) :: ch
      next_is = .false.
      if (c%pos > len(c%source)) return
      next_is = c%source(c%pos:c%pos) == ch
      if (next_is) c%pos = c%pos + 1
   end function next_is

   subroutine skip_blanks(c)
      type(json_cursor), intent(inout) :: c
      do while (c%pos <= len(c%source))
         select case (c%source(c%pos:c%pos))
         case (" ", achar(9), achar(13))
         case (achar(10))
            c%line = c%line + 1
         case default
            return
         end select
         c%pos = c%pos + 1
      end do
   end subroutine skip_blanks

   !> A string literal, unescaped (\uXXXX below 128 as the byte, above as UTF-8).
   subroutine parse_string(c, s, message)
      type(json_cursor), intent(inout) :: c
      character(len=:), allocatable, intent(out) :: s
      character(len=:), allocatable, intent(inout) :: message
      integer :: code, ios
      s = ""
      if (.not. next_is(c, '"')) then
         message = "expected a string"
         return
      end if
      do
         if (c%pos > len(c%source)) then
            message = "expected the end of a string, found the end of the text"
            return
         end if
         select case (c%source(c%pos:c%pos))
         case ('"')
            c%pos = c%pos + 1
            return
         case (achar(0):achar(31))
            message = "expected no control character inside a string"
            return
         case ("\")
            if (c%pos + 1 > len(c%source)) then
               message = "expected an escape after '\'"
               return
            end if
            select case (c%source(c%pos + 1:c%pos + 1))
            case ('"', "\", "/")
               s = s//c%source(c%pos + 1:c%pos + 1)
            case ("n")
               s = s//achar(10)
            case ("t")
               s = s//achar(9)
            case ("r")
               s = s//achar(13)
            case ("b")
               s = s//achar(8)
            case ("f")
               s = s//achar(12)
            case ("u")
               ios = 1
               if (c%pos + 5 <= len(c%source)) read(c%source(c%pos + 2:c%pos + 5), '(z4)', iostat=ios) code
               if (ios /= 0) then
                  message = "expected four hexadecimal digits after '\u'"
                  return
               end if
               s = s//utf8(code)
               c%pos = c%pos + 4
            case default
               message = "expected one of "" \ / b f n r t u after '\'"
               return
            end select
            c%pos = c%pos + 2
         case default
            s = s//c%source(c%pos:c%pos)
            c%pos = c%pos + 1
         end select
      end do
   end subroutine parse_string

   !> The UTF-8 bytes of a code point below 65536.
   pure function utf8(code) result(b)
      integer, intent(in) :: code
      character(len=:), allocatable :: b
      if (code < 128) then
         b = achar(code)
      else if (code < 2048) then
         b = achar(192 + code/64)//achar(128 + modulo(code, 64))
      else
         b = achar(224 + code/4096)//achar(128 + modulo(code/64, 64))//achar(128 + modulo(code, 64))
      end if
   end function utf8

   subroutine parse_word(c, path, word, kind, message)
      type(json_cursor), intent(inout) :: c
      character(len=*), intent(in) :: path, word
      integer, intent(in) :: kind
      character(len=:), allocatable, intent(inout) :: message
      if (c%pos + len(word) - 1 > len(c%source)) then
         message = "expected "//word
      else if (c%source(c%pos:c%pos + len(word) - 1) /= word) then
         message = "expected "//word
      else
         call add_leaf(c, path, word, kind)
         c%pos = c%pos + len(word)
      end if
   end subroutine parse_word

   !> A number: the longest run of number characters, which must read as a real.
   subroutine parse_number(c, path, message)
      type(json_cursor), intent(inout) :: c
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(inout) :: message
      integer :: first, ios
      real(dp) :: x
      first = c%pos
      do while (c%pos <= len(c%source))
         if (index("+-0123456789.eE", c%source(c%pos:c%pos)) == 0) exit
         c%pos = c%pos + 1
      end do
      ios = 1
      if (c%pos > first) read(c%source(first:c%pos - 1), *, iostat=ios) x
      if (ios /= 0) then
         message = "expected a value (object, array, string, number, true, false or null), found '"// &
            first_word(c%source(first:min(first + 11, len(c%source))))//"'"
         return
      end if
      call add_leaf(c, path, c%source(first:c%pos - 1), JSON_NUMBER)
   end subroutine parse_number

   !> The text up to its first blank or line end.
   pure function first_word(s) result(w)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: w
      integer :: k
      k = scan(s, " "//achar(9)//achar(10)//achar(13))
      if (k == 0) then
         w = s
      else
         w = s(1:k - 1)
      end if
   end function first_word

   subroutine add_leaf(c, path, text, kind)
      type(json_cursor), intent(inout) :: c
      character(len=*), intent(in) :: path, text
      integer, intent(in) :: kind
      type(json_leaf), allocatable :: more(:)
      integer :: k
      if (c%count == size(c%leaves)) then
         allocate(more(2*size(c%leaves)))
         do k = 1, c%count
            call move_alloc(c%leaves(k)%path, more(k)%path)
            call move_alloc(c%leaves(k)%text, more(k)%text)
            more(k)%kind = c%leaves(k)%kind
         end do
         call move_alloc(more, c%leaves)
      end if
      c%count = c%count + 1
      c%leaves(c%count)%path = path
      c%leaves(c%count)%text = text
      c%leaves(c%count)%kind = kind
   end subroutine add_leaf

   !> The index of the leaf at `path` (0: none).
   pure integer function leaf_index(leaves, path) result(k)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: path
      do k = 1, size(leaves)
         if (leaves(k)%path == path) return
      end do
      k = 0
   end function leaf_index

   !> The text of the leaf at `path` ("" when there is none).
   pure function leaf_text(leaves, path) result(t)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: t
      integer :: k
      k = leaf_index(leaves, path)
      t = ""
      if (k > 0) t = leaves(k)%text
   end function leaf_text

   !> The number at `path`; `fallback` when there is none or it is not a number.
   real(dp) function leaf_real(leaves, path, fallback) result(x)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: path
      real(dp), intent(in) :: fallback
      integer :: k, ios
      x = fallback
      k = leaf_index(leaves, path)
      if (k == 0) return
      if (leaves(k)%kind /= JSON_NUMBER) return
      read(leaves(k)%text, *, iostat=ios) x
      if (ios /= 0) x = fallback
   end function leaf_real

   !> How many elements the array at `path` has: the first n with a leaf below path[n].
   pure integer function leaf_count(leaves, path) result(n)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: path
      integer :: k, m, close_at, value, ios
      n = 0
      m = len(path)
      do k = 1, size(leaves)
         if (len(leaves(k)%path) <= m + 1) cycle
         if (leaves(k)%path(1:m + 1) /= path//"[") cycle
         close_at = index(leaves(k)%path(m + 2:), "]")
         if (close_at < 2) cycle
         read(leaves(k)%path(m + 2:m + close_at), *, iostat=ios) value
         if (ios == 0) n = max(n, value + 1)
      end do
   end function leaf_count
end module femcod_json_reader
