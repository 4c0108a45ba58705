!> The machine's physical memory, so that a run that cannot fit is refused with the
!> bytes it needs before it starts (Linux over-commits: a huge allocation may
!> "succeed" and the process be killed later when the pages are touched).
module femcod_memory
   use, intrinsic :: iso_c_binding, only: c_int, c_long
   use femcod_kinds, only: i8
   implicit none
   private
   public :: physical_memory, memory_text

   interface
      function c_sysconf(name) bind(c, name="sysconf") result(value)
         import :: c_int, c_long
         integer(c_int), value :: name
         integer(c_long) :: value
      end function c_sysconf
   end interface

   !> glibc's _SC_PAGESIZE and _SC_PHYS_PAGES.
   integer(c_int), parameter :: SC_PAGESIZE = 30, SC_PHYS_PAGES = 85

contains

   !> Physical memory in bytes (0 when the system does not say).
   function physical_memory() result(bytes)
      integer(i8) :: bytes
      integer(c_long) :: pages, page
      pages = c_sysconf(SC_PHYS_PAGES)
      page = c_sysconf(SC_PAGESIZE)
      bytes = 0
      if (pages > 0 .and. page > 0) bytes = int(pages, i8)*int(page, i8)
   end function physical_memory

   !> "N bytes (X GiB)".
   function memory_text(bytes) result(text)
      integer(i8), intent(in) :: bytes
      character(len=:), allocatable :: text
      character(len=48) :: buf
      write(buf, '(i0," bytes (",f0.1," GiB)")') bytes, real(bytes)/1024.0**3
      text = trim(buf)
   end function memory_text
end module femcod_memory
