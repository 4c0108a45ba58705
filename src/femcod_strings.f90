!> Small string helpers.
module femcod_strings
   use femcod_kinds, only: dp
   implicit none
   private
   public :: string_type, int_str, real_str, split_list

   !> A string of any length, for lists of arguments.
   type :: string_type
      character(len=:), allocatable :: s
   end type string_type

contains

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
