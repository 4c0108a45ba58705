!> Helpers shared by the test suites: scratch files and text checks.
module test_support
   implicit none
   private
   public :: write_text, read_text, scratch_path, contains_text, remove_scratch, file_exists

   character(len=*), parameter :: scratch_dir = "build/test-scratch"

contains

   !> A path in the scratch directory (created on first use).
   function scratch_path(name) result(path)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: path
      logical, save :: made = .false.
      if (.not. made) then
         call execute_command_line("mkdir -p "//scratch_dir)
         made = .true.
      end if
      path = scratch_dir//"/"//name
   end function scratch_path

   !> Write bytes to a file exactly (no added line end).
   subroutine write_text(path, text)
      character(len=*), intent(in) :: path, text
      integer :: unit
      open(newunit=unit, file=path, access="stream", form="unformatted", status="replace", action="write")
      write(unit) text
      close(unit)
   end subroutine write_text

   !> The bytes of a file ("" when it cannot be read).
   function read_text(path) result(text)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: text
      integer :: unit, ios, n
      open(newunit=unit, file=path, access="stream", form="unformatted", status="old", action="read", iostat=ios)
      if (ios /= 0) then
         text = ""
         return
      end if
      inquire(unit=unit, size=n)
      allocate(character(len=max(n, 0)) :: text)
      if (n > 0) read(unit, iostat=ios) text
      close(unit)
   end function read_text

   logical function file_exists(path)
      character(len=*), intent(in) :: path
      inquire(file=path, exist=file_exists)
   end function file_exists

   subroutine remove_scratch(path)
      character(len=*), intent(in) :: path
      integer :: unit, ios
      open(newunit=unit, file=path, status="old", iostat=ios)
      if (ios == 0) close(unit, status="delete")
   end subroutine remove_scratch

   pure logical function contains_text(text, part)
      character(len=*), intent(in) :: text, part
      contains_text = index(text, part) > 0
   end function contains_text
end module test_support
