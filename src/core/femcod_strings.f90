!> Small string helpers.
module femcod_strings
   use femcod_kinds, only: dp
   implicit none
   private
   public :: string_type, int_str, real_str, fixed_str, split_list, text_builder, add_line, built_text, without_trailing_zeros

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

   !> A decimal mantissa without trailing zeros after its point, nor a bare point
   !> ("2.500" -> "2.5", "3.000" -> "3"); text without a point is returned as it is.
   pure function without_trailing_zeros(s) result(t)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: t
      t = s
      if (index(t, ".") == 0) return
      do while (t(len(t):len(t)) == "0")
         t = t(1:len(t) - 1)
      end do
      if (t(len(t):len(t)) == ".") t = t(1:len(t) - 1)
   end function without_trailing_zeros

   !> Append `line` and a line end.
   pure subroutine add_line(builder, line)
      type(text_builder), intent(inout) :: builder
      character(len=*), intent(in) :: line
      character(len=:), allocatable :: bigger
      integer :: need
      need = builder%length + len(line) + 1
      if (.not. allocated(builder%buffer)) allocate(character(len=max(4096, 2*need)) :: builder%buffer)
      if (need > len(builder%buffer)) then
         allocate(character(len=2*need) :: bigger)
         bigger(1:builder%length) = builder%buffer(1:builder%length)
         call move_alloc(bigger, builder%buffer)
      end if
      builder%buffer(builder%length + 1:need) = line//new_line("a")
      builder%length = need
   end subroutine add_line

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
   pure function int_str(i) result(s)
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      character(len=12) :: buf
      write(buf, '(i0)') i
      s = trim(buf)
   end function int_str

   !> A real in `es` form with `digits` significant digits.
   function real_str(x, digits) result(s)
      real(dp), intent(in) :: x
      integer, intent(in) :: digits
      character(len=:), allocatable :: s
      character(len=40) :: buf, fmt
      write(fmt, '("(es",i0,".",i0,"e3)")') digits + 8, digits - 1
      write(buf, fmt) x
      s = trim(adjustl(buf))
   end function real_str

   !> A real in fixed-point form with `decimals` digits after the point (tables).
   function fixed_str(x, decimals) result(s)
      real(dp), intent(in) :: x
      integer, intent(in) :: decimals
      character(len=:), allocatable :: s
      character(len=40) :: buf, fmt
      write(fmt, '("(f0.",i0,")")') decimals
      write(buf, fmt) x
      s = trim(adjustl(buf))
      if (s(1:1) == ".") s = "0"//s
      if (s(1:min(2, len(s))) == "-.") s = "-0"//s(2:)
   end function fixed_str

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
end module femcod_strings
