!> Bruker/Veeco NanoScope files (`.di`, `.spm`, `.000`...), `FILE[:CHANNEL]`, the first
!> height channel by default: h_nm = raw * (the hard "@2:Z scale" value, V) /
!> 2^(8 bytes per pixel) * (the sensitivity it names, nm/V); rows are stored bottom to
!> top and come back top row first. The scan size, pixel size and instrument are kept.
!> Every field is checked against the file's size before it is used.
module femcod_nanoscope
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_strings, only: string_type, int_str, parse_integer, next_line, lower_case
   use femcod_files, only: read_file
   use femcod_height_map, only: height_map, unit_in_nm, check_size, starts_with_file
   implicit none
   private
   public :: read_nanoscope

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
            if (index(lower_case(section), "ciao image list") > 0) images = images + 1
            cycle
         end if
         if (index(lower_case(section), "ciao image list") == 0) cycle
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
         else if (lower_case(channel) == lower_case(kind_name) .or. lower_case(channel) == lower_case(label) .or. &
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
            if (index(lower_case(line), "ciao image list") > 0) k = k + 1
            cycle
         end if
         if (k /= chosen) then
            ! The scan list's size serves when the image list has none.
            if (k == 0 .and. field(line, key, value)) then
               if (lower_case(key) == "scan size") call scan_size(value, image%scan_x, image%scan_y, image%scan_unit)
            end if
            cycle
         end if
         if (.not. field(line, key, value)) cycle
         select case (lower_case(key))
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
               " holds "//int_str(length)//" bytes, not "//int_str(samples)//" x "//int_str(lines)//" x "// &
               int_str(bpp))
         else if (offset + length > file_size) then
            call set_error(status, STATUS_BAD_INPUT, path//": a corrupt (truncated) NanoScope file: channel "// &
               int_str(chosen)//" ends at byte "//int_str(offset + length)//", the file has "//int_str(file_size))
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
         if (index(lower_case(line), "\*ciao image list") == 1) c = c + 1
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
end module femcod_nanoscope
