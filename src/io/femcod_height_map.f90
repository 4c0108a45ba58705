!> The height map a file gives (nm) with what the file said about it, the length units the
!> readers take, and what every reader checks before it allocates (femcod_heights,
!> femcod_nanoscope).
module femcod_height_map
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_strings, only: string_type, int_str
   use femcod_files, only: path_exists, path_is_directory
   use femcod_memory, only: physical_memory, memory_text, usable_text
   use femcod_problem, only: MAX_NP
   implicit none
   private
   public :: height_map, HEIGHT_UNITS, unit_in_nm, check_size, starts_with_file

   !> The units --height-unit takes.
   character(len=*), parameter :: HEIGHT_UNITS = "m|mm|um|nm|A|pm"

   !> A height map and what its file said about it.
   type :: height_map
      !> Heights (nm), z(i, j) row i (from the top), column j.
      real(dp), allocatable :: z(:, :)
      !> Pixel size along the rows (x) and the columns (y) in nm; 0 when the file does not
      !> give it. Scan size (nm) likewise.
      real(dp) :: pixel_x = 0, pixel_y = 0, scan_x = 0, scan_y = 0
      !> The format, the channel read, the instrument, the heights' unit in the file.
      character(len=:), allocatable :: format, channel, instrument, unit
      !> What the reader noticed that the user should know.
      type(string_type), allocatable :: warnings(:)
   end type height_map

contains

   !> nm per unit of a length unit ("m", "mm", "um", "~m", "µm", "nm", "A", "Å", "pm");
   !> 0 for an unknown one.
   pure real(dp) function unit_in_nm(unit)
      character(len=*), intent(in) :: unit
      select case (trim(adjustl(unit)))
      case ("m")
         unit_in_nm = 1.0e9_dp
      case ("mm")
         unit_in_nm = 1.0e6_dp
      case ("um", "~m", "µm", "μm", "micron")
         unit_in_nm = 1.0e3_dp
      case ("nm")
         unit_in_nm = 1
      case ("A", "Å", "Angstrom")
         unit_in_nm = 0.1_dp
      case ("pm")
         unit_in_nm = 1.0e-3_dp
      case default
         unit_in_nm = 0
      end select
   end function unit_in_nm

   !> Whether the file begins with `prefix`.
   logical function starts_with_file(path, prefix)
      character(len=*), intent(in) :: path, prefix
      character(len=len(prefix)) :: head
      integer :: unit, ios
      starts_with_file = .false.
      if (path_is_directory(path) .or. .not. path_exists(path)) return
      open(newunit=unit, file=path, access="stream", form="unformatted", action="read", status="old", iostat=ios)
      if (ios /= 0) return
      read(unit, iostat=ios) head
      close(unit)
      starts_with_file = ios == 0 .and. head == prefix
   end function starts_with_file

   !> Rows and columns of a map within MAX_NP and the machine's memory, before allocating.
   subroutine check_size(path, rows, cols, status)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: rows, cols
      type(status_type), intent(inout) :: status
      if (status%code /= 0) return
      if (rows < 1 .or. cols < 1) then
         call set_error(status, STATUS_BAD_INPUT, path//": the dataset is empty ("//int_str(rows)//" x "// &
            int_str(cols)//"): expected a matrix of heights, at least 1 x 1")
      else if (rows > MAX_NP .or. cols > MAX_NP) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected at most "//int_str(MAX_NP)//" x "// &
            int_str(MAX_NP)//" heights, found "//int_str(rows)//" x "//int_str(cols))
      else if (physical_memory() > 0 .and. 16*rows*cols > physical_memory()) then
         call set_error(status, STATUS_BAD_INPUT, path//": "//int_str(rows)//" x "//int_str(cols)//" heights need "// &
            memory_text(16*rows*cols)//", this run may use "//usable_text(physical_memory()))
      end if
   end subroutine check_size
end module femcod_height_map
