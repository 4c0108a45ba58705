!> Helpers shared by the test suites: scratch files and text checks, and the solvers'
!> diagnostics read from a result (femcod_contact_result's accessors, one number each).
module test_support
   use femcod_kinds, only: dp
   use femcod_contact_result, only: contact_result, event_path_diagnostics, legacy_diagnostics, event_checks, &
      legacy_checks
   implicit none
   private
   public :: write_text, read_text, scratch_path, contains_text, remove_scratch, file_exists, occurrences
   public :: pivot_loss_of, condition_of, missed_final_check_of, fft_steps_of

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

   !> How many times `piece` occurs in `text` (not overlapping).
   pure integer function occurrences(text, piece) result(n)
      character(len=*), intent(in) :: text, piece
      integer :: start, k
      n = 0
      start = 1
      do
         k = index(text(start:), piece)
         if (k == 0) return
         n = n + 1
         start = start + k - 1 + len(piece)
      end do
   end function occurrences

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
   !> The legacy solver's largest TRFACT pivot loss (1 for another solver).
   real(dp) function pivot_loss_of(res) result(r)
      type(contact_result), intent(in) :: res
      type(legacy_diagnostics) :: checks
      checks = legacy_checks(res)
      r = checks%pivot_loss
   end function pivot_loss_of

   !> The legacy solver's largest condition estimate (0 for another solver).
   real(dp) function condition_of(res) result(r)
      type(contact_result), intent(in) :: res
      type(legacy_diagnostics) :: checks
      checks = legacy_checks(res)
      r = checks%condition
   end function condition_of

   !> The event path's penetrating pixels found by its final check.
   integer function missed_final_check_of(res) result(n)
      type(contact_result), intent(in) :: res
      type(event_path_diagnostics) :: checks
      checks = event_checks(res)
      n = checks%missed_final_check
   end function missed_final_check_of

   !> The event path's steps searched by the full-field FFT.
   integer function fft_steps_of(res) result(n)
      type(contact_result), intent(in) :: res
      type(event_path_diagnostics) :: checks
      checks = event_checks(res)
      n = checks%fft_steps
   end function fft_steps_of
end module test_support
