!> Height maps from files: ASCII matrices and HDF5 datasets (`FILE.h5:/dataset`), and
!> the scenes of `mkdeck matrix`, `run --lower/--upper` and the studies built from them.
module femcod_heights
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_strings, only: int_str, parse_real
   use femcod_files, only: path_exists, path_is_directory
   use femcod_hdf5, only: h5_file, h5_open, h5_read, h5_close
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem
   implicit none
   private
   public :: read_heights, read_ascii_matrix, load_scene

contains

   !> Build the problem of a spec; a "matrix" scene first reads its heights from
   !> spec%matrix_file and, when named, the other surface's from spec%second_file.
   subroutine load_scene(spec, problem, status)
      type(scene_spec), intent(in) :: spec
      type(contact_problem), intent(out) :: problem
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: heights(:, :), second(:, :)
      if (spec%kind /= "matrix") then
         call build_problem(spec, problem, status)
         return
      end if
      call read_heights(spec%matrix_file, heights, status)
      if (status%code /= 0) return
      allocate(second(0, 0))
      if (allocated(spec%second_file)) then
         if (spec%second_file /= "") then
            call read_heights(spec%second_file, second, status)
            if (status%code /= 0) return
         end if
      end if
      call build_problem(spec, problem, status, heights, second)
   end subroutine load_scene

   !> Heights (nm) from `FILE` (an ASCII matrix) or `FILE.h5:/path` (a square 2-D HDF5
   !> dataset, C order: data[i, j] is row i, column j; any numeric type).
   subroutine read_heights(path, z, status)
      character(len=*), intent(in) :: path
      real(dp), allocatable, intent(out) :: z(:, :)
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      integer :: colon
      colon = index(path, ":/", back=.true.)
      if (colon == 0) then
         call read_ascii_matrix(path, z, status)
         return
      end if
      associate(fname => path(1:colon - 1), dataset => path(colon + 1:))
         if (path_is_directory(fname) .or. .not. path_exists(fname)) then
            call set_error(status, STATUS_BAD_INPUT, fname//": expected an HDF5 file of heights, found none")
            return
         end if
         call h5_open(fname, file, status, STATUS_BAD_INPUT)
         call h5_read(file, dataset, z, status, STATUS_BAD_INPUT)
         call h5_close(file, status)
         if (status%code /= 0) return
         if (size(z, 1) /= size(z, 2) .or. size(z) == 0) then
            call set_error(status, STATUS_BAD_INPUT, path//": expected a square matrix of heights, found "// &
               int_str(size(z, 1))//" x "//int_str(size(z, 2)))
            return
         end if
         if (.not. all(ieee_is_finite(z))) then
            call set_error(status, STATUS_BAD_INPUT, path//": expected finite heights (nm), found NaN or Inf")
            return
         end if
      end associate
   end subroutine read_heights

   !> Read an ASCII height matrix (nm), one image row per line, values separated by
   !> blanks, tabs or commas, lines starting with '#' ignored (Gwyddion export). The
   !> matrix must be square.
   subroutine read_ascii_matrix(path, z, status)
      character(len=*), intent(in) :: path
      real(dp), allocatable, intent(out) :: z(:, :)
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: line
      real(dp), allocatable :: row(:), rows(:, :)
      integer :: unit, ios, nrow, ncol, lineno
      logical :: ok
      if (path_is_directory(path) .or. .not. path_exists(path)) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a height-matrix file, found none")
         return
      end if
      open(newunit=unit, file=path, action="read", status="old", iostat=ios)
      if (ios /= 0) then
         call set_error(status, STATUS_BAD_INPUT, path//": cannot open the height matrix")
         return
      end if
      nrow = 0
      ncol = 0
      lineno = 0
      allocate(rows(0, 0))
      do
         call read_line(unit, line, ios)
         if (ios /= 0) exit
         lineno = lineno + 1
         if (len_trim(line) == 0) cycle
         if (adjustl(line(1:1)) == "#" .or. line(1:1) == "#") cycle
         call split_reals(line, row, ok)
         if (.not. ok) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)// &
               ": expected a row of finite numbers (nm), found '"//line(1:min(len(line), 40))//"'")
            close(unit)
            return
         end if
         if (nrow == 0) then
            ncol = size(row)
            deallocate(rows)
            allocate(rows(ncol, ncol))
         end if
         if (size(row) /= ncol) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)//": expected "// &
               int_str(ncol)//" values as in the first row, found "//(int_str(size(row))))
            close(unit)
            return
         end if
         nrow = nrow + 1
         if (nrow > ncol) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)// &
               ": expected a square matrix of "//int_str(ncol)//" rows, found more rows")
            close(unit)
            return
         end if
         rows(:, nrow) = row
      end do
      close(unit)
      if (nrow == 0 .or. nrow /= ncol) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a square matrix of heights, found "// &
            int_str(nrow)//" rows of "//int_str(ncol)//" values")
         return
      end if
      z = transpose(rows)
   end subroutine read_ascii_matrix

   !> Read one line of any length.
   subroutine read_line(unit, line, ios)
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: line
      integer, intent(out) :: ios
      character(len=4096) :: buf
      integer :: nread
      line = ""
      do
         read(unit, '(a)', advance="no", iostat=ios, size=nread) buf
         line = line//buf(1:nread)
         if (ios /= 0) exit
      end do
      if (is_iostat_eor(ios)) ios = 0
      if (len(line) > 0) then
         if (line(len(line):len(line)) == achar(13)) line = line(1:len(line) - 1)
      end if
   end subroutine read_line

   !> Split a line into reals.
   subroutine split_reals(line, values, ok)
      character(len=*), intent(in) :: line
      real(dp), allocatable, intent(out) :: values(:)
      logical, intent(out) :: ok
      integer :: i, start, n
      real(dp) :: v
      real(dp), allocatable :: tmp(:)
      allocate(tmp(len(line)/2 + 1))
      n = 0
      ok = .true.
      i = 1
      do while (i <= len(line))
         if (is_sep(line(i:i))) then
            i = i + 1
            cycle
         end if
         start = i
         do while (i <= len(line))
            if (is_sep(line(i:i))) exit
            i = i + 1
         end do
         call parse_real(line(start:i - 1), v, ok)
         if (.not. ok) return
         n = n + 1
         tmp(n) = v
      end do
      values = tmp(1:n)
      ok = n > 0
   contains
      pure logical function is_sep(c)
         character(len=1), intent(in) :: c
         is_sep = c == " " .or. c == achar(9) .or. c == "," .or. c == achar(13)
      end function is_sep
   end subroutine split_reals
end module femcod_heights
