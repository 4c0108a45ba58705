!> The memory a run may use, so that a run that cannot fit is refused with the bytes it
!> needs before it starts (Linux over-commits: a huge allocation may "succeed" and the
!> process be killed later when the pages are touched). On a cluster that is the job's
!> limit, not the machine's: the smaller of the physical memory and the memory limit of
!> the process's control group (cgroup v2 memory.max, v1 memory.limit_in_bytes), which
!> is where Slurm and container runtimes put a job's --mem. The environment variable
!> FEMCOD_MEMORY (bytes, or a number with K, M, G or T: KiB to TiB) lowers it further, for
!> a run that shares a machine or a node without a memory limit of its own.
module femcod_memory
   use, intrinsic :: iso_c_binding, only: c_int, c_long
   use femcod_kinds, only: i8
   implicit none
   private
   public :: physical_memory, memory_text, usable_text, resident_bytes, peak_resident_bytes, available_memory
   public :: memory_setting, MEMORY_VARIABLE

   !> The environment variable that caps the memory femcod may use.
   character(len=*), parameter :: MEMORY_VARIABLE = "FEMCOD_MEMORY"

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

   !> The memory this process may use, in bytes (0 when the system does not say).
   function physical_memory() result(bytes)
      integer(i8) :: bytes
      integer(i8) :: limit
      integer(c_long) :: pages, page
      pages = c_sysconf(SC_PHYS_PAGES)
      page = c_sysconf(SC_PAGESIZE)
      bytes = 0
      if (pages > 0 .and. page > 0) bytes = int(pages, i8)*int(page, i8)
      limit = cgroup_limit()
      if (limit > 0 .and. (bytes == 0 .or. limit < bytes)) bytes = limit
      call memory_setting(limit)
      if (limit > 0 .and. (bytes == 0 .or. limit < bytes)) bytes = limit
   end function physical_memory

   !> FEMCOD_MEMORY in bytes: 0 when it is not set, -1 when it is set but is not a
   !> positive number of bytes with an optional K, M, G or T (powers of 1024).
   subroutine memory_setting(bytes)
      integer(i8), intent(out) :: bytes
      character(len=64) :: text
      integer :: length, status, ios, last
      real(kind(1.0d0)) :: value, factor
      bytes = 0
      call get_environment_variable(MEMORY_VARIABLE, text, length, status)
      if (status == 1) return
      bytes = -1
      if (status /= 0 .or. length == 0) return
      text = adjustl(text)
      last = len_trim(text)
      factor = 1
      select case (text(last:last))
      case ("K", "k")
         factor = 1024.0d0
      case ("M", "m")
         factor = 1024.0d0**2
      case ("G", "g")
         factor = 1024.0d0**3
      case ("T", "t")
         factor = 1024.0d0**4
      end select
      if (factor > 1) last = last - 1
      if (last < 1) return
      if (verify(text(1:last), "0123456789.") /= 0) return
      read(text(1:last), *, iostat=ios) value
      if (ios /= 0 .or. .not. value*factor >= 1 .or. value*factor > 2.0d0**62) return
      bytes = int(value*factor, i8)
   end subroutine memory_setting

   !> The memory limit of this process's cgroup in bytes (0: none found, or unlimited).
   function cgroup_limit() result(bytes)
      integer(i8) :: bytes
      character(len=512) :: line
      integer :: unit, ios, colon2
      bytes = 0
      open(newunit=unit, file="/proc/self/cgroup", action="read", status="old", iostat=ios)
      if (ios /= 0) return
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         colon2 = index(line, ":", back=.true.)
         if (colon2 == 0) cycle
         if (index(line, "0::") == 1) then
            call smaller(read_limit("/sys/fs/cgroup"//trim(line(colon2 + 1:))//"/memory.max"))
         else if (index(line, ":memory:") > 0) then
            call smaller(read_limit("/sys/fs/cgroup/memory"//trim(line(colon2 + 1:))//"/memory.limit_in_bytes"))
            call smaller(read_limit("/sys/fs/cgroup/memory/memory.limit_in_bytes"))
         end if
      end do
      close(unit)
   contains
      subroutine smaller(v)
         integer(i8), intent(in) :: v
         if (v > 0 .and. (bytes == 0 .or. v < bytes)) bytes = v
      end subroutine smaller
   end function cgroup_limit

   !> A limit file's number of bytes; 0 for "max", a huge value (no limit), or none.
   function read_limit(path) result(bytes)
      character(len=*), intent(in) :: path
      integer(i8) :: bytes
      integer :: unit, ios
      bytes = 0
      open(newunit=unit, file=path, action="read", status="old", iostat=ios)
      if (ios /= 0) return
      read(unit, *, iostat=ios) bytes
      close(unit)
      if (ios /= 0 .or. bytes >= 2_i8**60) bytes = 0
   end function read_limit

   !> The memory this process holds now (VmRSS of /proc/self/status, bytes; 0 where the
   !> system has no such file).
   function resident_bytes() result(bytes)
      integer(i8) :: bytes
      bytes = status_field("VmRSS:")
   end function resident_bytes

   !> What a solve may still take (bytes): the memory this process may use less what it
   !> holds now; 0 where the system does not say (then nothing is checked).
   function available_memory() result(bytes)
      integer(i8) :: bytes
      bytes = physical_memory()
      if (bytes > 0) bytes = max(bytes - resident_bytes(), 1_i8)
   end function available_memory

   !> The most memory this process has held (VmHWM, bytes; 0 where unknown).
   function peak_resident_bytes() result(bytes)
      integer(i8) :: bytes
      bytes = status_field("VmHWM:")
   end function peak_resident_bytes

   !> A "Key:   N kB" line of /proc/self/status, in bytes.
   function status_field(key) result(bytes)
      character(len=*), intent(in) :: key
      integer(i8) :: bytes, kb
      character(len=256) :: line
      integer :: unit, ios
      bytes = 0
      open(newunit=unit, file="/proc/self/status", action="read", status="old", iostat=ios)
      if (ios /= 0) return
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (index(line, key) == 1) then
            read(line(len(key) + 1:), *, iostat=ios) kb
            if (ios == 0) bytes = 1024*kb
            exit
         end if
      end do
      close(unit)
   end function status_field

   !> "N bytes (X.Y UNIT)", UNIT the largest of KiB, MiB, GiB and TiB that X is at least
   !> 1 of (bytes alone below 1 KiB).
   !> The memory a run may still use, as text: memory_text, or "nothing" where the
   !> process already holds more than it may use (available_memory's 1 byte).
   function usable_text(bytes) result(text)
      integer(i8), intent(in) :: bytes
      character(len=:), allocatable :: text
      if (bytes <= 1) then
         text = "nothing (the process already holds more than the memory it may use: FEMCOD_MEMORY, the job's "// &
            "limit or the machine's)"
      else
         text = memory_text(bytes)
      end if
   end function usable_text

   function memory_text(bytes) result(text)
      integer(i8), intent(in) :: bytes
      character(len=:), allocatable :: text
      character(len=*), parameter :: UNITS(4) = ["KiB", "MiB", "GiB", "TiB"]
      character(len=48) :: buf
      integer :: k
      write(buf, '(i0," bytes")') bytes
      text = trim(buf)
      do k = size(UNITS), 1, -1
         if (real(bytes, kind(1.0d0)) >= 1024.0d0**k) then
            write(buf, '(f0.1)') real(bytes, kind(1.0d0))/1024.0d0**k
            text = text//" ("//trim(buf)//" "//UNITS(k)//")"
            exit
         end if
      end do
   end function memory_text
end module femcod_memory
