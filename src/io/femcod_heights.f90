!> Height maps from files, read exactly or refused:
!> - ASCII matrices, one image row per line (values separated by blanks, tabs or
!>   commas), with an optional Gwyddion export header (English or German: `# Channel`,
!>   `# Width`/`# Breite`, `# Height`/`# Hoehe`, `# Value units`): the header's units are
!>   honoured and the pixel size comes from the width;
!> - HDF5 datasets, `FILE.h5:/dataset` (numeric, C order: data[i, j] is row i, column j);
!> - Bruker/Veeco NanoScope files (`.di`, `.spm`, `.000`...), `FILE[:CHANNEL]`
!>   (femcod_nanoscope).
!> Every size is checked before anything is allocated, every value before it is used.
!> Heights come back in nm, row 1 at the top of the image.
module femcod_heights
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use femcod_kinds, only: dp, i8
   use femcod_arrays, only: grow
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_USAGE
   use femcod_strings, only: string_type, int_str, parse_real, format_real, append_string, sig_str, lower_case
   use femcod_surfaces, only: plane_tilt, block_average
   use femcod_files, only: path_exists, path_is_directory, read_file
   use femcod_hdf5, only: h5_file, h5_open, h5_read, h5_close, h5_rank_and_dims
   use femcod_problem, only: contact_problem, MAX_NP
   use femcod_generate, only: scene_spec, build_problem
   use femcod_height_map, only: height_map, HEIGHT_UNITS, unit_in_nm, check_size, starts_with_file
   use femcod_nanoscope, only: read_nanoscope
   implicit none
   private
   public :: height_map, read_height_map, read_heights, read_ascii_matrix, load_scene, is_height_file, unit_in_nm
   public :: height_file_path, looks_like_height_matrix
   public :: HEIGHT_UNITS

contains

   !> The file a height path reads: FILE of FILE.h5:/dataset and of FILE:CHANNEL.
   function height_file_path(path) result(file)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: file, channel
      integer :: colon
      colon = index(path, ":/", back=.true.)
      if (colon > 0) then
         file = path(1:colon - 1)
      else
         call split_channel(path, file, channel)
      end if
   end function height_file_path

   !> Whether `path` names heights rather than a deck: an HDF5 dataset (FILE.h5:/path), a
   !> NanoScope file (by its first bytes, with or without :CHANNEL) or a Gwyddion export.
   logical function is_height_file(path)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: file, channel
      is_height_file = index(path, ":/") > 0
      if (is_height_file) return
      call split_channel(path, file, channel)
      is_height_file = starts_with_file(file, "\*File list") .or. starts_with_file(file, "# Channel:") .or. &
         starts_with_file(file, "# Kanal:")
   end function is_height_file

   !> Whether a file that failed to read as a deck reads as a plain matrix of heights: its
   !> first two lines (past '#' comments) are rows of the same two or more numbers. For
   !> the message that says --pixel is what it needs.
   logical function looks_like_height_matrix(path) result(yes)
      character(len=*), intent(in) :: path
      character(len=4096) :: line
      integer :: unit, ios, rows, counts(2)
      yes = .false.
      if (path_is_directory(path) .or. .not. path_exists(path)) return
      open(newunit=unit, file=path, action="read", status="old", iostat=ios)
      if (ios /= 0) return
      rows = 0
      do while (rows < 2)
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         line = adjustl(line)
         if (line == "" .or. line(1:1) == "#") cycle
         rows = rows + 1
         counts(rows) = number_count(trim(line))
      end do
      close(unit)
      if (rows == 2) yes = counts(1) >= 2 .and. counts(1) == counts(2)
   contains
      !> The count of blank-separated numbers in `text` (0 when a token is not one).
      integer function number_count(text) result(n)
         character(len=*), intent(in) :: text
         integer :: i, start
         real(dp) :: v
         logical :: ok
         n = 0
         i = 1
         do while (i <= len(text))
            if (text(i:i) == " " .or. text(i:i) == achar(9)) then
               i = i + 1
               cycle
            end if
            start = i
            do while (i <= len(text))
               if (text(i:i) == " " .or. text(i:i) == achar(9)) exit
               i = i + 1
            end do
            call parse_real(text(start:i - 1), v, ok)
            if (.not. ok) then
               n = 0
               return
            end if
            n = n + 1
         end do
      end function number_count
   end function looks_like_height_matrix

   !> Read the heights `path` names (see the module's head). `height_unit` ("" for nm)
   !> is the unit of files that do not state theirs; a file that does, in another unit,
   !> is refused.
   subroutine read_height_map(path, map, status, height_unit)
      character(len=*), intent(in) :: path
      type(height_map), intent(out) :: map
      type(status_type), intent(inout) :: status
      character(len=*), intent(in), optional :: height_unit
      character(len=:), allocatable :: file, channel, given
      real(dp) :: scale
      integer :: bad(2)
      allocate(map%warnings(0))
      map%channel = ""
      map%instrument = ""
      map%unit = ""
      given = ""
      if (present(height_unit)) given = height_unit
      if (index(path, ":/") > 0) then
         call read_hdf5_heights(path, map, status)
      else
         call split_channel(path, file, channel)
         if (starts_with_file(file, "\*File list") .or. starts_with_file(file, "\*Force file list")) then
            call read_nanoscope(file, channel, map, status)
         else if (channel /= "") then
            call set_error(status, STATUS_BAD_INPUT, path//": a :CHANNEL goes with NanoScope files, and "// &
               file//" is not one")
         else
            call read_ascii_matrix(path, map, status)
         end if
      end if
      if (status%code /= 0) return
      ! Units: the file's own, else --height-unit, else nm.
      if (map%unit /= "" .and. given /= "") then
         if (unit_in_nm(given) /= unit_in_nm(map%unit)) then
            call set_error(status, STATUS_BAD_INPUT, path//": the file gives its heights in "//map%unit// &
               "; --height-unit "//given//" contradicts it")
            return
         end if
      end if
      if (map%unit == "") then
         map%unit = "nm"
         if (given /= "") map%unit = given
         scale = unit_in_nm(map%unit)
         if (abs(scale - 1) > 0) map%z = map%z*scale
      end if
      if (.not. all(ieee_is_finite(map%z))) then
         bad = findloc(ieee_is_finite(map%z), .false.)
         call set_error(status, STATUS_BAD_INPUT, path//": expected finite heights (nm), found "// &
            trim(merge("NaN", "Inf", ieee_is_nan(map%z(bad(1), bad(2)))))//" at row "//int_str(bad(1))// &
            ", column "//int_str(bad(2))//" (the first of "//int_str(count(.not. ieee_is_finite(map%z)))//")")
         return
      end if
      if (maxval(abs(map%z)) > 1.0e12_dp) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected heights within 1e12 nm (1 km), found "// &
            format_real(maxval(abs(map%z)))//" nm (heights in other units: --height-unit)")
         return
      end if
      if (maxval(map%z) - minval(map%z) > 0 .and. maxval(map%z) - minval(map%z) < 1.0e-3_dp) call warn(map, &
         path//": the heights span only "//format_real(maxval(map%z) - minval(map%z))//" nm; if the file holds "// &
         "metres, give --height-unit m")
   end subroutine read_height_map

   !> The heights alone (nm), for callers that need no metadata.
   subroutine read_heights(path, z, status)
      character(len=*), intent(in) :: path
      real(dp), allocatable, intent(out) :: z(:, :)
      type(status_type), intent(inout) :: status
      type(height_map) :: map
      call read_height_map(path, map, status)
      if (status%code == 0) call move_alloc(map%z, z)
   end subroutine read_heights

   !> Build the problem of a spec; a "matrix" scene first reads its heights from
   !> spec%matrix_file and, when named, the other surface's from spec%second_file (in
   !> spec%height_unit when the files do not say). A pixel size the files give serves when
   !> the spec has none; `notes` says what was read, one line per file, and what the
   !> reader warns about.
   subroutine load_scene(spec, problem, status, notes, warnings)
      type(scene_spec), intent(in) :: spec
      type(contact_problem), intent(out) :: problem
      type(status_type), intent(inout) :: status
      type(string_type), allocatable, intent(out), optional :: notes(:), warnings(:)
      type(height_map) :: first, other
      type(scene_spec) :: used
      !> A plane rising more than this many times the rms roughness about it is reported.
      real(dp), parameter :: TILT_RATIO = 10
      real(dp) :: rise, roughness
      type(string_type), allocatable :: lines(:), warned(:)
      real(dp), allocatable :: second(:, :)
      allocate(lines(0), warned(0))
      if (present(notes)) allocate(notes(0))
      if (present(warnings)) allocate(warnings(0))
      if (spec%kind /= "matrix") then
         call build_problem(spec, problem, status)
         if (present(notes)) notes = lines
         if (present(warnings)) warnings = warned
         return
      end if
      used = spec
      call read_height_map(spec%matrix_file, first, status, trim(spec%height_unit))
      if (status%code /= 0) return
      if (present(warnings)) warnings = first%warnings
      call append_string(lines, describe(spec%matrix_file, first))
      warned = [warned, first%warnings]
      allocate(second(0, 0))
      if (allocated(spec%second_file)) then
         if (spec%second_file /= "") then
            call read_height_map(spec%second_file, other, status, trim(spec%height_unit))
            if (status%code /= 0) return
            call append_string(lines, describe(spec%second_file, other))
            warned = [warned, other%warnings]
            call same_grid(spec%matrix_file, first, spec%second_file, other, status)
            if (status%code /= 0) return
            call move_alloc(other%z, second)
         end if
      end if
      call square_grid(spec%matrix_file, first, status)
      if (status%code /= 0) return
      if (.not. used%pixel > 0) then
         if (.not. first%pixel_x > 0) then
            call set_error(status, STATUS_USAGE, spec%matrix_file//" does not give its pixel size: give --pixel D "// &
               "(nm)")
            return
         end if
         used%pixel = first%pixel_x
      else if (first%pixel_x > 0) then
         ! Nested: .and. may evaluate the ratio for a file without a pixel size.
         if (abs(used%pixel/first%pixel_x - 1) > 1.0e-6_dp) call append_string(warned, "--pixel "// &
            format_real(used%pixel)//" nm replaces the "//format_real(first%pixel_x)//" nm of "//spec%matrix_file)
      end if
      if (used%pixel < 1.0e-3_dp) call append_string(warned, "a pixel of "//format_real(used%pixel)// &
         " nm: if that is metres, give the size in nm")
      ! --average N: N x N blocks into one pixel, both surfaces alike.
      if (spec%average > 1) then
         if (mod(size(first%z, 1), spec%average) /= 0) then
            call set_error(status, STATUS_USAGE, "--average "//int_str(spec%average)//": the "// &
               int_str(size(first%z, 1))//" x "//int_str(size(first%z, 1))//" heights of "//spec%matrix_file// &
               " are not a whole number of "//int_str(spec%average)//" x "//int_str(spec%average)//" blocks")
            return
         end if
         first%z = block_average(first%z, spec%average)
         if (size(second) > 0) second = block_average(second, spec%average)
         used%pixel = used%pixel*spec%average
         call append_string(lines, int_str(spec%average)//" x "//int_str(spec%average)//" blocks averaged: "// &
            int_str(size(first%z, 1))//" x "//int_str(size(first%z, 1))//" pixels of "//format_real(used%pixel)//" nm")
      end if
      ! A tilt far above the roughness is most often the scan's mounting: say so.
      if (.not. spec%plane) then
         call plane_tilt(first%z, rise, roughness)
         if (rise > TILT_RATIO*roughness .and. roughness > 0) then
            call append_string(warned, spec%matrix_file//": its least-squares plane rises "//sig_str(rise, 3)// &
               " nm across the scan, "//sig_str(rise/roughness, 3)//" times the roughness about it ("// &
               sig_str(roughness, 3)//" nm rms): give --remove-plane if the tilt is the mounting, not the surface")
         else if (rise > 0 .and. roughness == 0) then
            call append_string(warned, spec%matrix_file//": its heights are a tilted plane (rising "// &
               sig_str(rise, 3)//" nm across the scan) with no roughness about it")
         end if
      end if
      ! --maxcont is the user's: name it when the scan is too small for it.
      if (used%maxcont > size(first%z, 1)**2) then
         call set_error(status, STATUS_USAGE, "--maxcont "//int_str(used%maxcont)//" is above the "// &
            int_str(size(first%z, 1)**2)//" pixels of "//spec%matrix_file//" (NP^2, the most contacts there are)")
         return
      end if
      call build_problem(used, problem, status, first%z, second)
      if (present(notes)) notes = lines
      if (present(warnings)) warnings = warned
   end subroutine load_scene

   !> A height file in one line: name, format, channel, instrument, grid, scan and pixel.
   function describe(path, map) result(text)
      character(len=*), intent(in) :: path
      type(height_map), intent(in) :: map
      character(len=:), allocatable :: text
      text = path//": "//map%format
      if (map%channel /= "") text = text//", channel "//map%channel
      if (map%instrument /= "") text = text//", "//map%instrument
      text = text//", "//int_str(size(map%z, 1))//" x "//int_str(size(map%z, 2))//" heights in "//map%unit
      if (map%scan_x > 0) text = text//", scan "//format_real(map%scan_x)//" x "//format_real(map%scan_y)//" nm"
      if (map%pixel_x > 0) text = text//", pixel "//format_real(map%pixel_x)//" nm"
   end function describe

   !> Two surfaces pressed together share one grid: the same number of heights and, where
   !> both files give it, the same pixel. femcod does not resample: two different grids
   !> are refused, naming both (exit 3).
   subroutine same_grid(path1, map1, path2, map2, status)
      character(len=*), intent(in) :: path1, path2
      type(height_map), intent(in) :: map1, map2
      type(status_type), intent(inout) :: status
      if (any(shape(map1%z) /= shape(map2%z))) then
         call set_error(status, STATUS_BAD_INPUT, path1//" has "//int_str(size(map1%z, 1))//" x "// &
            int_str(size(map1%z, 2))//" heights, "//path2//" has "//int_str(size(map2%z, 1))//" x "// &
            int_str(size(map2%z, 2))//": the two surfaces must share one grid (femcod does not resample)")
      else if (map1%pixel_x > 0 .and. map2%pixel_x > 0) then
         if (abs(map1%pixel_x/map2%pixel_x - 1) > 1.0e-6_dp) call set_error(status, STATUS_BAD_INPUT, path1// &
            " has pixels of "//format_real(map1%pixel_x)//" nm, "//path2//" of "//format_real(map2%pixel_x)// &
            " nm: the two surfaces must share one pixel (femcod does not resample; bring them to one grid first)")
      end if
   end subroutine same_grid

   !> femcod's grids are square with square pixels.
   subroutine square_grid(path, map, status)
      character(len=*), intent(in) :: path
      type(height_map), intent(in) :: map
      type(status_type), intent(inout) :: status
      if (size(map%z, 1) /= size(map%z, 2)) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a square matrix of heights, found "// &
            int_str(size(map%z, 1))//" rows of "//int_str(size(map%z, 2))//" values")
      else if (map%pixel_x > 0 .and. map%pixel_y > 0) then
         ! Nested: Fortran's .and. may evaluate the ratio even when a size is 0.
         if (abs(map%pixel_x/map%pixel_y - 1) > 1.0e-6_dp) call set_error(status, STATUS_BAD_INPUT, path// &
            ": expected square pixels, found "//format_real(map%pixel_x)//" x "//format_real(map%pixel_y)//" nm")
      end if
   end subroutine square_grid

   subroutine warn(map, text)
      type(height_map), intent(inout) :: map
      character(len=*), intent(in) :: text
      call append_string(map%warnings, text)
   end subroutine warn

   !> FILE[:CHANNEL]: the channel is what follows the last colon when what precedes it is
   !> an existing file ("" otherwise).
   subroutine split_channel(path, file, channel)
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(out) :: file, channel
      integer :: colon
      file = path
      channel = ""
      colon = index(path, ":", back=.true.)
      if (colon > 1) then
         if (path_exists(path(1:colon - 1)) .and. .not. path_exists(path)) then
            file = path(1:colon - 1)
            channel = path(colon + 1:)
         end if
      end if
   end subroutine split_channel

   ! ---- HDF5 ---------------------------------------------------------------------

   subroutine read_hdf5_heights(path, map, status)
      character(len=*), intent(in) :: path
      type(height_map), intent(inout) :: map
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      integer(i8) :: dims(7)
      integer :: colon, rank
      map%format = "HDF5 dataset"
      colon = index(path, ":/", back=.true.)
      associate(fname => path(1:colon - 1), dataset => path(colon + 1:))
         if (path_is_directory(fname) .or. .not. path_exists(fname)) then
            call set_error(status, STATUS_BAD_INPUT, fname//": expected an HDF5 file of heights, found none")
            return
         end if
         call h5_open(fname, file, status, STATUS_BAD_INPUT)
         call h5_rank_and_dims(file, dataset, rank, dims, status, STATUS_BAD_INPUT)
         if (status%code == 0 .and. rank == 2) call check_size(path, dims(1), dims(2), status)
         call h5_read(file, dataset, map%z, status, STATUS_BAD_INPUT)
         call h5_close(file, status)
      end associate
   end subroutine read_hdf5_heights

   ! ---- ASCII matrices and Gwyddion exports ---------------------------------------

   !> An ASCII height matrix, one image row per line; lines starting with '#' are
   !> comments, except the Gwyddion header fields (Width/Breite, Height/Hoehe, Value
   !> units, Channel/Kanal). The rows are kept as read (no square shape assumed here).
   subroutine read_ascii_matrix(path, map, status)
      character(len=*), intent(in) :: path
      type(height_map), intent(inout) :: map
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: text, line
      real(dp), allocatable :: values(:)
      real(dp) :: width, height
      integer :: a, b, lineno, nrow, ncol, n, first, k
      logical :: gwyddion
      map%format = "ASCII matrix"
      call read_file(path, "a height-matrix file", text, status)
      if (status%code /= 0) return
      if (index(text, achar(0)) > 0) then
         if (index(text, achar(137)//"HDF") == 1) then
            call set_error(status, STATUS_BAD_INPUT, path//": an HDF5 file: name the dataset of heights, "// &
               path//":/PATH (for example "//path//":/heights)")
         else
            call set_error(status, STATUS_BAD_INPUT, path//": expected a text matrix of heights, found binary content")
         end if
         return
      end if
      allocate(values(1024))
      n = 0
      nrow = 0
      ncol = 0
      lineno = 0
      width = 0
      height = 0
      gwyddion = .false.
      a = 1
      do while (a <= len(text))
         b = index(text(a:), new_line("a"))
         if (b == 0) then
            b = len(text) + 1
         else
            b = a + b - 1
         end if
         line = text(a:b - 1)
         a = b + 1
         lineno = lineno + 1
         if (len(line) > 0) then
            if (line(len(line):len(line)) == achar(13)) line = line(1:len(line) - 1)
         end if
         if (len_trim(line) == 0) cycle
         line = adjustl(line)
         if (line(1:1) == "#") then
            call gwyddion_field(path, lineno, line, map, width, height, gwyddion, status)
            if (status%code /= 0) return
            cycle
         end if
         first = n
         call split_reals(line, values, n, status)
         if (status%code /= 0) then
            status%message = path//":"//int_str(lineno)//": "//status%message
            return
         end if
         if (nrow == 0) then
            ncol = n - first
            if (ncol > MAX_NP) then
               call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)//": expected at most "// &
                  int_str(MAX_NP)//" values in a row, found "//int_str(ncol))
               return
            end if
         else if (n - first /= ncol) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)//": expected "// &
               int_str(ncol)//" values as in the first row, found "//int_str(n - first))
            return
         end if
         nrow = nrow + 1
         if (nrow > MAX_NP) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)//": expected at most "// &
               int_str(MAX_NP)//" rows, found more")
            return
         end if
      end do
      if (nrow == 0) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a matrix of heights, found no rows")
         return
      end if
      if (status%code /= 0) return
      allocate(map%z(nrow, ncol))
      do k = 1, nrow
         map%z(k, :) = values((k - 1)*ncol + 1:k*ncol)
      end do
      if (gwyddion) map%format = "Gwyddion ASCII export"
      if (map%unit /= "") map%z = map%z*unit_in_nm(map%unit)
      if (width > 0) map%scan_x = width
      if (height > 0) map%scan_y = height
      if (width > 0) map%pixel_x = width/ncol
      if (height > 0) map%pixel_y = height/nrow
      if (width > 0 .and. .not. height > 0) map%pixel_y = map%pixel_x
   end subroutine read_ascii_matrix

   !> A Gwyddion header field, "# Key: value" (line `lineno` of `path`): the scan's width
   !> and height (nm), the channel, the heights' unit; other comments are skipped.
   subroutine gwyddion_field(path, lineno, line, map, width, height, gwyddion, status)
      character(len=*), intent(in) :: path, line
      integer, intent(in) :: lineno
      type(height_map), intent(inout) :: map
      real(dp), intent(inout) :: width, height
      logical, intent(inout) :: gwyddion
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: key, value
      real(dp) :: factor
      integer :: colon
      colon = index(line, ":")
      if (colon == 0) return
      key = lower_case(trim(adjustl(line(2:colon - 1))))
      value = trim(adjustl(line(colon + 1:)))
      select case (key)
      case ("width", "breite")
         call length_field(path, lineno, value, width, status)
         gwyddion = .true.
      case ("height", "höhe", "hoehe")
         call length_field(path, lineno, value, height, status)
         gwyddion = .true.
      case ("channel", "kanal")
         map%channel = value
         gwyddion = .true.
      case ("value units", "werteeinheit", "werteeinheiten")
         factor = unit_in_nm(value)
         if (.not. factor > 0) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)// &
               ": expected the heights' unit (m, mm, um, nm, A, pm), found '"//value//"'")
            return
         end if
         map%unit = value
         gwyddion = .true.
      end select
   end subroutine gwyddion_field

   !> "12.34 µm" -> nm (line `lineno` of `path` for the message).
   subroutine length_field(path, lineno, field, length, status)
      character(len=*), intent(in) :: path, field
      integer, intent(in) :: lineno
      real(dp), intent(out) :: length
      type(status_type), intent(inout) :: status
      integer :: blank
      logical :: ok
      blank = index(field, " ")
      length = 0
      if (blank > 1) then
         call parse_real(field(1:blank - 1), length, ok)
         if (ok) length = length*unit_in_nm(field(blank + 1:))
         if (ok .and. length > 0) return
      end if
      call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)//": expected a length with its unit "// &
         "(for example 12.34 um), found '"//field//"'")
      length = 0
   end subroutine length_field

   !> Append the reals of a line to `vals` (grown by doubling) at n.
   subroutine split_reals(row, vals, n, st)
      character(len=*), intent(in) :: row
      real(dp), allocatable, intent(inout) :: vals(:)
      integer, intent(inout) :: n
      type(status_type), intent(inout) :: st
      integer :: i, start, column
      real(dp) :: v
      logical :: ok
      i = 1
      column = 0
      do while (i <= len(row))
         if (is_separator(row(i:i))) then
            i = i + 1
            cycle
         end if
         start = i
         do while (i <= len(row))
            if (is_separator(row(i:i))) exit
            i = i + 1
         end do
         column = column + 1
         call parse_real(row(start:i - 1), v, ok)
         if (.not. ok) then
            ! Name the value itself: the line's head need not hold it.
            call set_error(st, STATUS_BAD_INPUT, "column "//int_str(column)//": expected a finite height "// &
               "(nm), found '"//row(start:min(i - 1, start + 39))//"'")
            return
         end if
         if (n == size(vals)) then
            call grow(vals, 2*size(vals))
         end if
         n = n + 1
         vals(n) = v
      end do
   end subroutine split_reals

   pure logical function is_separator(c)
      character(len=1), intent(in) :: c
      is_separator = c == " " .or. c == achar(9) .or. c == "," .or. c == achar(13)
   end function is_separator
end module femcod_heights
