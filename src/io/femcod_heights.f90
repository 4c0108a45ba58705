!> Height maps from files, read exactly or refused:
!> - ASCII matrices, one image row per line (values separated by blanks, tabs or
!>   commas), with an optional Gwyddion export header (English or German: `# Channel`,
!>   `# Width`/`# Breite`, `# Height`/`# Hoehe`, `# Value units`): the header's units are
!>   honoured and the pixel size comes from the width;
!> - HDF5 datasets, `FILE.h5:/dataset` (numeric, C order: data[i, j] is row i, column j);
!> - Bruker/Veeco NanoScope files (`.di`, `.spm`, `.000`...), `FILE[:CHANNEL]`, the first
!>   height channel by default: h_nm = raw * (the hard "@2:Z scale" value, V) /
!>   2^(8 bytes per pixel) * (the sensitivity it names, nm/V); rows are stored bottom to
!>   top. The scan size, pixel size and instrument are kept.
!> Every size is checked before anything is allocated, every value before it is used.
!> Heights come back in nm, row 1 at the top of the image.
module femcod_heights
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use, intrinsic :: iso_fortran_env, only: int16, int32
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_USAGE
   use femcod_strings, only: string_type, int_str, parse_real, parse_integer, format_real, append_string, sig_str, &
      next_line
   use femcod_surfaces, only: plane_tilt, block_average
   use femcod_files, only: path_exists, path_is_directory, read_file
   use femcod_hdf5, only: h5_file, h5_open, h5_read, h5_close, h5_rank_and_dims
   use femcod_memory, only: physical_memory, memory_text, usable_text
   use femcod_problem, only: contact_problem, MAX_NP
   use femcod_generate, only: scene_spec, build_problem
   implicit none
   private
   public :: height_map, read_height_map, read_heights, read_ascii_matrix, load_scene, is_height_file, unit_in_nm
   public :: height_file_path, looks_like_height_matrix
   public :: HEIGHT_UNITS

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

   !> The fields of one NanoScope image that reading it needs: the data's offset and
   !> length (bytes), bytes per pixel, samples per line, lines, the Z scale's hard value
   !> and unit, the sensitivity it refers to, the scan size and its unit.
   type :: nanoscope_image
      integer(i8) :: offset = -1, length = -1
      integer :: bpp = 0, samples = 0, lines = 0
      real(dp) :: hard = 0, scan_x = 0, scan_y = 0
      character(len=:), allocatable :: hard_unit, sens_ref, scan_unit
   end type nanoscope_image

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

   !> Rows and columns of a map within MAX_NP and the machine's memory, before allocating.
   subroutine check_size(path, rows, cols, status)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: rows, cols
      type(status_type), intent(inout) :: status
      if (status%code /= 0) return
      if (rows < 1 .or. cols < 1) then
         call set_error(status, STATUS_BAD_INPUT, path//": the dataset is empty ("//i8_text(rows)//" x "// &
            i8_text(cols)//"): expected a matrix of heights, at least 1 x 1")
      else if (rows > MAX_NP .or. cols > MAX_NP) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected at most "//int_str(MAX_NP)//" x "// &
            int_str(MAX_NP)//" heights, found "//i8_text(rows)//" x "//i8_text(cols))
      else if (physical_memory() > 0 .and. 16*rows*cols > physical_memory()) then
         call set_error(status, STATUS_BAD_INPUT, path//": "//i8_text(rows)//" x "//i8_text(cols)//" heights need "// &
            memory_text(16*rows*cols)//", this run may use "//usable_text(physical_memory()))
      end if
   end subroutine check_size

   function i8_text(v) result(text)
      integer(i8), intent(in) :: v
      character(len=:), allocatable :: text
      character(len=24) :: buf
      write(buf, '(i0)') v
      text = trim(buf)
   end function i8_text

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
      key = lower(trim(adjustl(line(2:colon - 1))))
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
      real(dp), allocatable :: grown(:)
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
            allocate(grown(2*size(vals)))
            grown(1:n) = vals(1:n)
            call move_alloc(grown, vals)
         end if
         n = n + 1
         vals(n) = v
      end do
   end subroutine split_reals

   pure logical function is_separator(c)
      character(len=1), intent(in) :: c
      is_separator = c == " " .or. c == achar(9) .or. c == "," .or. c == achar(13)
   end function is_separator

   pure function lower(s) result(t)
      character(len=*), intent(in) :: s
      character(len=len(s)) :: t
      integer :: k
      t = s
      do k = 1, len(s)
         if (s(k:k) >= "A" .and. s(k:k) <= "Z") t(k:k) = achar(iachar(s(k:k)) + 32)
      end do
   end function lower

   ! ---- NanoScope ----------------------------------------------------------------


   !> A Bruker/Veeco NanoScope file: the header ("\key: value" lines up to "\*File list
   !> end") and the image of one channel (little-endian signed integers).
   subroutine read_nanoscope(path, channel, map, status)
      character(len=*), intent(in) :: path, channel
      type(height_map), intent(inout) :: map
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: bytes, header, names, description
      type(string_type), allocatable :: sens_name(:)
      real(dp), allocatable :: sens_value(:)
      type(nanoscope_image) :: image
      integer(i8) :: file_size
      integer :: chosen, k, r, i
      real(dp) :: sens
      map%format = "NanoScope"
      if (starts_with_file(path, "\*Force file list")) then
         call set_error(status, STATUS_BAD_INPUT, path//": a NanoScope force curve, not an image of heights")
         return
      end if
      call read_file(path, "a NanoScope file", bytes, status)
      if (status%code /= 0) return
      file_size = len(bytes, kind=i8)
      k = index(bytes, "\*File list end")
      if (k == 0) then
         call set_error(status, STATUS_BAD_INPUT, path//": a corrupt NanoScope file: its header has no end "// &
            "(\*File list end)")
         return
      end if
      header = bytes(1:k - 1)
      call nanoscope_sensitivities(header, sens_name, sens_value, description)
      call nanoscope_channel(header, channel, chosen, names)
      if (chosen == 0) then
         if (channel == "") then
            call set_error(status, STATUS_BAD_INPUT, path//": no height channel (Height or ZSensor); channels: "// &
               trim(names)//" (choose one with FILE:CHANNEL)")
         else
            call set_error(status, STATUS_BAD_INPUT, path//": no channel '"//channel//"'; channels: "//trim(names))
         end if
         return
      end if
      image = nanoscope_image_fields(header, chosen)
      map%channel = int_str(chosen)//" "//trim(kind_name_of(header, chosen))
      call check_nanoscope_image(path, chosen, image, file_size, status)
      if (status%code /= 0) return
      sens = 0
      do i = 1, size(sens_name)
         if (sens_name(i)%s == image%sens_ref(index(image%sens_ref, " ") + 1:)) sens = sens_value(i)
      end do
      if (.not. sens > 0) then
         call set_error(status, STATUS_BAD_INPUT, path//": a corrupt NanoScope file: no sensitivity '"// &
            image%sens_ref//"' in nm/V for channel "//int_str(chosen))
         return
      end if
      ! The data, rows bottom to top, little-endian signed integers.
      associate(lines => image%lines, samples => image%samples, bpp => image%bpp, offset => image%offset)
         allocate(map%z(lines, samples))
         do r = 1, lines
            associate(start => offset + int(r - 1, i8)*samples*bpp)
               do i = 1, samples
                  map%z(lines - r + 1, i) = raw_value(bytes(start + (i - 1)*bpp + 1:start + i*bpp))
               end do
            end associate
         end do
         map%z = map%z*(image%hard/2.0_dp**(8*bpp))*sens
         map%unit = "nm"
         if (description /= "") map%instrument = "NanoScope "//description
         if (image%scan_x > 0) then
            map%scan_x = image%scan_x*unit_in_nm(image%scan_unit)
            map%scan_y = image%scan_y*unit_in_nm(image%scan_unit)
            map%pixel_x = map%scan_x/samples
            map%pixel_y = map%scan_y/lines
         end if
      end associate
   end subroutine read_nanoscope

   !> The header's sensitivities (\@Sens. NAME: V value nm/V, in nm/V) and its first
   !> description.
   subroutine nanoscope_sensitivities(header, sens_name, sens_value, description)
      character(len=*), intent(in) :: header
      type(string_type), allocatable, intent(out) :: sens_name(:)
      real(dp), allocatable, intent(out) :: sens_value(:)
      character(len=:), allocatable, intent(out) :: description
      character(len=:), allocatable :: line, key, value
      real(dp) :: x
      integer :: a
      logical :: ok
      allocate(sens_name(0), sens_value(0))
      description = ""
      a = 1
      do while (next_line(header, a, line))
         if (.not. field(line, key, value)) cycle
         if (index(key, "@Sens. ") == 1) then
            call sensitivity(value, x, ok)
            if (ok) then
               sens_name = [sens_name, string_type(key(8:))]
               sens_value = [sens_value, x]
            end if
         else if (key == "Description" .and. description == "") then
            description = value
         end if
      end do
   end subroutine nanoscope_sensitivities

   !> The image list: the channel asked for (its number, kind or label; "": the first
   !> Height or ZSensor), 0 when none is; `names` lists them all for the message.
   subroutine nanoscope_channel(header, channel, chosen, names)
      character(len=*), intent(in) :: header, channel
      integer, intent(out) :: chosen
      character(len=:), allocatable, intent(out) :: names
      character(len=:), allocatable :: line, section, key, value, kind_name, label
      integer :: a, b, images
      images = 0
      chosen = 0
      names = ""
      section = ""
      a = 1
      do while (next_line(header, a, line))
         if (line(1:min(2, len(line))) == "\*") then
            section = line
            if (index(lower(section), "ciao image list") > 0) images = images + 1
            cycle
         end if
         if (index(lower(section), "ciao image list") == 0) cycle
         if (.not. field(line, key, value)) cycle
         if (key /= "@2:Image Data") cycle
         b = index(value, "[")
         kind_name = value(b + 1:index(value, "]") - 1)
         label = value(index(value, '"') + 1:index(value, '"', back=.true.) - 1)
         if (names /= "") names = names//", "
         names = names//int_str(images)//" "//kind_name//' "'//label//'"'
         if (chosen /= 0) cycle
         if (channel == "") then
            if (kind_name == "Height" .or. kind_name == "ZSensor") chosen = images
         else if (lower(channel) == lower(kind_name) .or. lower(channel) == lower(label) .or. &
            channel == int_str(images)) then
            chosen = images
         end if
      end do
   end subroutine nanoscope_channel

   !> The fields of image `chosen` (the scan list's size where the image has none).
   function nanoscope_image_fields(header, chosen) result(image)
      character(len=*), intent(in) :: header
      integer, intent(in) :: chosen
      type(nanoscope_image) :: image
      character(len=:), allocatable :: line, key, value
      integer :: a, b, k
      logical :: ok
      image%hard_unit = ""
      image%sens_ref = ""
      image%scan_unit = ""
      k = 0
      a = 1
      do while (next_line(header, a, line))
         if (line(1:min(2, len(line))) == "\*") then
            if (index(lower(line), "ciao image list") > 0) k = k + 1
            cycle
         end if
         if (k /= chosen) then
            ! The scan list's size serves when the image list has none.
            if (k == 0 .and. field(line, key, value)) then
               if (lower(key) == "scan size") call scan_size(value, image%scan_x, image%scan_y, image%scan_unit)
            end if
            cycle
         end if
         if (.not. field(line, key, value)) cycle
         select case (lower(key))
         case ("data offset")
            call read_i8(value, image%offset)
         case ("data length")
            call read_i8(value, image%length)
         case ("bytes/pixel")
            call parse_integer(value, image%bpp, ok)
         case ("samps/line")
            call parse_integer(value, image%samples, ok)
         case ("number of lines")
            call parse_integer(value, image%lines, ok)
         case ("scan size")
            call scan_size(value, image%scan_x, image%scan_y, image%scan_unit)
         case ("@2:z scale")
            ! V [Sens. Zscan] (0.002934346 V/LSB) 192.3024 V: the hard value after ")".
            image%sens_ref = value(index(value, "[") + 1:index(value, "]") - 1)
            b = index(value, ")", back=.true.)
            call number_and_unit(value(b + 1:), image%hard, image%hard_unit)
         end select
      end do
   end function nanoscope_image_fields

   !> The image's fields hold together and fit in the file (`file_size` bytes), its size
   !> is one femcod takes, and its Z scale is in volts (a height).
   subroutine check_nanoscope_image(path, chosen, image, file_size, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: chosen
      type(nanoscope_image), intent(in) :: image
      integer(i8), intent(in) :: file_size
      type(status_type), intent(inout) :: status
      associate(bpp => image%bpp, samples => image%samples, lines => image%lines, offset => image%offset, &
         length => image%length)
         if (.not. (bpp == 2 .or. bpp == 4) .or. samples < 1 .or. lines < 1 .or. offset < 0 .or. length < 0) then
            call set_error(status, STATUS_BAD_INPUT, path//": a corrupt NanoScope file: channel "//int_str(chosen)// &
               " lacks its data offset, length, bytes per pixel or size")
         else if (int(samples, i8)*lines*bpp /= length) then
            call set_error(status, STATUS_BAD_INPUT, path//": a corrupt NanoScope file: channel "//int_str(chosen)// &
               " holds "//i8_text(length)//" bytes, not "//int_str(samples)//" x "//int_str(lines)//" x "// &
               int_str(bpp))
         else if (offset + length > file_size) then
            call set_error(status, STATUS_BAD_INPUT, path//": a corrupt (truncated) NanoScope file: channel "// &
               int_str(chosen)//" ends at byte "//i8_text(offset + length)//", the file has "//i8_text(file_size))
         else
            call check_size(path, int(lines, i8), int(samples, i8), status)
            if (status%code == 0 .and. image%hard_unit /= "V") call set_error(status, STATUS_BAD_INPUT, path// &
               ": channel "//int_str(chosen)//" is not a height: its Z scale is in '"//image%hard_unit//"', not V")
         end if
      end associate
   end subroutine check_nanoscope_image

   !> The kind of image `which` of the header ([Height], [ZSensor], ...).
   function kind_name_of(header, which) result(text)
      character(len=*), intent(in) :: header
      integer, intent(in) :: which
      character(len=:), allocatable :: text, line
      integer :: c, p, q
      text = ""
      c = 0
      p = 1
      do while (next_line(header, p, line))
         if (index(lower(line), "\*ciao image list") == 1) c = c + 1
         if (c == which .and. index(line, "\@2:Image Data:") == 1) then
            q = index(line, "[")
            text = line(q + 1:index(line, "]") - 1)
            return
         end if
      end do
   end function kind_name_of

   !> A little-endian signed integer of 2 or 4 bytes.
   pure real(dp) function raw_value(chunk)
      character(len=*), intent(in) :: chunk
      integer(i8) :: u
      integer :: j
      u = 0
      do j = len(chunk), 1, -1
         u = u*256 + iachar(chunk(j:j))
      end do
      if (u >= 2_i8**(8*len(chunk) - 1)) u = u - 2_i8**(8*len(chunk))
      raw_value = real(u, dp)
   end function raw_value

   subroutine read_i8(text, v)
      character(len=*), intent(in) :: text
      integer(i8), intent(out) :: v
      integer :: ios
      read(text, *, iostat=ios) v
      if (ios /= 0) v = -1
   end subroutine read_i8

   !> "V 13.22830 nm/V" -> 13.2283 (nm/V); other length units per V converted.
   subroutine sensitivity(text, v, good)
      character(len=*), intent(in) :: text
      real(dp), intent(out) :: v
      logical, intent(out) :: good
      character(len=:), allocatable :: u
      real(dp) :: f
      good = .false.
      v = 0
      if (index(text, "V ") /= 1) return
      call number_and_unit(text(3:), v, u)
      if (index(u, "/V") == 0) return
      f = unit_in_nm(u(1:index(u, "/V") - 1))
      good = f > 0 .and. v > 0
      v = v*f
   end subroutine sensitivity

   !> "300 300 nm" or "1 1 ~m" or "300 nm" -> x, y, unit.
   subroutine scan_size(text, x, y, u)
      character(len=*), intent(in) :: text
      real(dp), intent(out) :: x, y
      character(len=:), allocatable, intent(out) :: u
      integer :: ios
      character(len=32) :: w(3)
      w = ""
      read(text, *, iostat=ios) w
      x = 0
      y = 0
      u = ""
      if (ios /= 0) read(text, *, iostat=ios) w(1:2)
      if (w(3) == "") then
         read(w(1), *, iostat=ios) x
         y = x
         u = trim(w(2))
      else
         read(w(1), *, iostat=ios) x
         read(w(2), *, iostat=ios) y
         u = trim(w(3))
      end if
      if (ios /= 0 .or. unit_in_nm(u) == 0) then
         x = 0
         y = 0
      end if
   end subroutine scan_size

   !> " 192.3024 V" -> 192.3024, "V".
   subroutine number_and_unit(text, v, u)
      character(len=*), intent(in) :: text
      real(dp), intent(out) :: v
      character(len=:), allocatable, intent(out) :: u
      character(len=:), allocatable :: t
      integer :: blank, ios
      t = trim(adjustl(text))
      blank = index(t, " ")
      v = 0
      u = ""
      if (blank == 0) return
      read(t(1:blank - 1), *, iostat=ios) v
      if (ios /= 0) v = 0
      u = trim(adjustl(t(blank + 1:)))
   end subroutine number_and_unit


   !> "\Key: value" -> key, value; false for other lines.
   logical function field(line, key, value)
      character(len=*), intent(in) :: line
      character(len=:), allocatable, intent(out) :: key, value
      integer :: colon
      field = .false.
      key = ""
      value = ""
      if (len(line) < 2) return
      if (line(1:1) /= "\") return
      colon = index(line, ": ")
      if (colon == 0) then
         if (line(len(line):len(line)) /= ":") return
         colon = len(line)
      end if
      key = line(2:colon - 1)
      value = trim(adjustl(line(min(colon + 1, len(line) + 1):)))
      field = .true.
   end function field
end module femcod_heights
