!> Height files in their native formats (io/femcod_heights): NanoScope and Gwyddion
!> exports from ../shared/data/afm/native (skipped where that folder is absent; their
!> expected values are those of SOURCES.md there, from SurfaceTopography's own tests),
!> and small files of each format written here with values known by construction.
module test_heights
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: string_type
   use femcod_heights, only: height_map, read_height_map, is_height_file
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_cli, only: run_femcod
   use test_support, only: scratch_path, write_text, read_text, file_exists, contains_text
   use test_results, only: self_command
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string, skip_test
   implicit none
   private
   public :: collect_heights

   character(len=*), parameter :: native = "../shared/data/afm/native/"

contains

   subroutine collect_heights(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("NanoScope 2-byte (Bruker D3100): rms 24.721922 nm, pixel, instrument", test_di2), &
         new_unittest("NanoScope 4-byte (Dimension Icon, ZSensor): rms 5.831926 nm", test_di5), &
         new_unittest("a corrupt NanoScope file is refused, never a crash", test_di_corrupted), &
         new_unittest("NanoScope written here: scaling, rows bottom to top, channels, truncation", test_nanoscope_made), &
         new_unittest("Gwyddion exports, English and German: metres to nm, width and height", test_gwyddion), &
         new_unittest("run with a Gwyddion export: pixel from the width, units from the header", test_gwyddion_run), &
         new_unittest("--height-unit for plain matrices; refused against a file's own unit", test_height_unit), &
         new_unittest("a tilt far above the roughness is reported; --remove-plane silences it", test_tilt_warning), &
         new_unittest("mkdeck matrix --average N: block means by hand, N times the pixel; a remainder refused", &
            test_average) &
         ]
   end subroutine collect_heights

   !> rms about the mean of a map.
   pure real(dp) function rms(z)
      real(dp), intent(in) :: z(:, :)
      rms = sqrt(sum((z - sum(z)/size(z))**2)/size(z))
   end function rms

   logical function have_native(error)
      type(error_type), allocatable, intent(out) :: error
      have_native = file_exists(native//"SOURCES.md") .or. file_exists(native//"di-2.di")
      if (.not. have_native) call skip_test(error, native//" is not on this machine")
   end function have_native

   subroutine test_di2(error)
      type(error_type), allocatable, intent(out) :: error
      type(height_map) :: map
      type(status_type) :: status
      if (.not. have_native(error)) return
      call read_height_map(native//"di-2.di", map, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, size(map%z, 1) == 512 .and. size(map%z, 2) == 512, "512 x 512")
      if (allocated(error)) return
      ! SOURCES.md: "rms height after removing the mean 24.721922 nm" (8 digits).
      call check(error, rms(map%z), 24.721922_dp, rel=.true., thr=1.0e-7_dp, message="rms")
      if (allocated(error)) return
      ! The header: Scan size 300 300 nm, 512 samples a line.
      call check(error, map%pixel_x, 300.0_dp/512, rel=.true., thr=1.0e-15_dp, message="pixel")
      if (allocated(error)) return
      call check(error, contains_text(map%instrument, "D3100") .and. contains_text(map%channel, "Height"), &
         "instrument and channel: "//map%instrument//", "//map%channel)
      if (allocated(error)) return
      call check(error, is_height_file(native//"di-2.di") .and. is_height_file(native//"di-2.di:Height"), &
         "recognised by its content")
   end subroutine test_di2

   subroutine test_di5(error)
      type(error_type), allocatable, intent(out) :: error
      type(height_map) :: map
      type(status_type) :: status
      if (.not. have_native(error)) return
      call read_height_map(native//"di-5.di", map, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      ! SOURCES.md: the first image channel, ZSensor, rms 5.831926 nm.
      call check(error, rms(map%z), 5.831926_dp, rel=.true., thr=1.0e-7_dp, message="rms")
      if (allocated(error)) return
      ! Scan Size 1 1 ~m: 1000 nm over 512 samples.
      call check(error, map%pixel_x, 1000.0_dp/512, rel=.true., thr=1.0e-15_dp, message="pixel")
      if (allocated(error)) return
      ! The second channel by name is not a height (its Z scale names another sensitivity).
      call read_height_map(native//"di-5.di:ZSensor", map, status)
      call check(error, status%code == 0 .and. abs(rms(map%z)/5.831926_dp - 1) < 1.0e-7_dp, "ZSensor by name")
   end subroutine test_di5

   subroutine test_di_corrupted(error)
      type(error_type), allocatable, intent(out) :: error
      type(height_map) :: map
      type(status_type) :: status
      integer :: code
      if (.not. have_native(error)) return
      call read_height_map(native//"di_corrupted.di", map, status)
      call check(error, status%code == 3 .and. contains_text(status%message, "corrupt"), "refused: "//status%message)
      if (allocated(error)) return
      call run_femcod([string_type("run"), string_type("--lower"), string_type(native//"di_corrupted.di"), &
         string_type("-o"), string_type(scratch_path("corrupt")), string_type("--quiet")], code)
      call check(error, code, 3, "exit code")
      if (allocated(error)) return
      call check(error, .not. file_exists(scratch_path("corrupt.h5")), "no result")
   end subroutine test_di_corrupted

   !> A NanoScope file of 4 x 3 2-byte pixels written here: a height channel with raw
   !> values 1..12 (row by row from the bottom), Z scale 2 V, sensitivity 65536 nm/V, so
   !> each step is raw * 2/2^16 * 65536 = 2 raw nm; a second channel "Phase".
   subroutine test_nanoscope_made(error)
      type(error_type), allocatable, intent(out) :: error
      type(height_map) :: map
      type(status_type) :: status
      character(len=:), allocatable :: path, text, head, data
      integer :: k, i, j
      character(len=1), parameter :: cr = achar(13), lf = achar(10)
      path = scratch_path("made.spm")
      data = ""
      do k = 1, 12
         data = data//achar(k)//achar(0)
      end do
      do k = 1, 12
         data = data//achar(255)//achar(255)
      end do
      head = "\*File list"//cr//lf//"\Version: 0x05310001"//cr//lf//"\Description: Test instrument"//cr//lf// &
         "\*Scanner list"//cr//lf//"\@Sens. Zscan: V 65536 nm/V"//cr//lf//"\@Sens. Phase: V 1 deg/V"//cr//lf// &
         image(1024, "Height", "Zscan", "2 V")//image(1024 + 24, "Phase", "Phase", "90 deg")//"\*File list end"//cr//lf
      text = head//repeat(achar(0), 1024 - len(head))//data
      call write_text(path, text)
      call read_height_map(path, map, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, size(map%z, 1) == 4 .and. size(map%z, 2) == 3, "4 lines of 3 samples")
      if (allocated(error)) return
      ! File row r (from the bottom) is image row 5 - r; raw value (r-1)*3 + j.
      do i = 1, 4
         do j = 1, 3
            call check(error, map%z(i, j), 2.0_dp*((4 - i)*3 + j), message="height ("//to_string(i)//", "// &
               to_string(j)//")")
            if (allocated(error)) return
         end do
      end do
      call check(error, map%pixel_x, 4.0_dp, thr=1.0e-12_dp, message="pixel: 12 nm over 3 samples")
      if (allocated(error)) return
      call read_height_map(path//":Phase", map, status)
      call check(error, status%code == 3 .and. contains_text(status%message, "not a height"), "Phase: "//status%message)
      if (allocated(error)) return
      status = status_type()
      call read_height_map(path//":Friction", map, status)
      call check(error, status%code == 3 .and. contains_text(status%message, "no channel 'Friction'") .and. &
         contains_text(status%message, "Phase"), "unknown channel: "//status%message)
      if (allocated(error)) return
      status = status_type()
      call write_text(path, text(1:len(text) - 30))
      call read_height_map(path, map, status)
      call check(error, status%code == 3 .and. contains_text(status%message, "truncated"), "truncated: "// &
         status%message)
   contains
      function image(offset, kind, sens, hard) result(lines)
         integer, intent(in) :: offset
         character(len=*), intent(in) :: kind, sens, hard
         character(len=:), allocatable :: lines
         lines = "\*Ciao image list"//cr//lf//"\Data offset: "//to_string(offset)//cr//lf//"\Data length: 24"//cr//lf// &
            "\Bytes/pixel: 2"//cr//lf//"\Samps/line: 3"//cr//lf//"\Number of lines: 4"//cr//lf// &
            "\Scan Size: 12 16 nm"//cr//lf//'\@2:Image Data: S ['//kind//'] "'//kind//'"'//cr//lf// &
            "\@2:Z scale: V [Sens. "//sens//"] (0.1 V/LSB) "//hard//cr//lf
      end function image
   end subroutine test_nanoscope_made

   subroutine test_gwyddion(error)
      type(error_type), allocatable, intent(out) :: error
      type(height_map) :: map
      type(status_type) :: status
      character(len=*), parameter :: files(2) = [character(len=27) :: "gwyddion-export-english.txt", &
         "gwyddion-export-german.txt"]
      integer :: k
      if (.not. have_native(error)) return
      do k = 1, 2
         call read_height_map(native//trim(files(k)), map, status)
         call check(error, status%code, 0, trim(files(k))//": "//status%message)
         if (allocated(error)) return
         ! SOURCES.md: 3 columns x 4 rows, width 12.34 um, height 5678.9 nm, values in m.
         call check(error, size(map%z, 1) == 4 .and. size(map%z, 2) == 3, trim(files(k))//": 4 rows of 3")
         if (allocated(error)) return
         call check(error, map%z(1, 2), 1.5e9_dp, rel=.true., thr=1.0e-15_dp, message=trim(files(k))//": 1.5 m")
         if (allocated(error)) return
         call check(error, map%z(2, 3), -6.0e9_dp, rel=.true., thr=1.0e-15_dp, message=trim(files(k))//": -6 m")
         if (allocated(error)) return
         call check(error, map%pixel_x, 12340.0_dp/3, rel=.true., thr=1.0e-14_dp, message=trim(files(k))//": width")
         if (allocated(error)) return
         call check(error, map%pixel_y, 5678.9_dp/4, rel=.true., thr=1.0e-14_dp, message=trim(files(k))//": height")
         if (allocated(error)) return
         call check(error, map%channel, "My Channel Name")
         if (allocated(error)) return
      end do
   end subroutine test_gwyddion

   !> A square Gwyddion export written here: 4 x 4 heights in um, width 8 nm: the run takes
   !> a pixel of 2 nm and heights x 1000.
   subroutine test_gwyddion_run(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: path, prefix, text
      character(len=*), parameter :: nl = new_line("a")
      integer :: code
      path = scratch_path("gwy.txt")
      prefix = scratch_path("gwy_run")
      call write_text(path, "# Channel: Topography"//nl//"# Width: 8 nm"//nl//"# Height: 8 nm"//nl// &
         "# Value units: um"//nl//"0 0.001 0 0"//nl//"0 0.002 0.001 0"//nl//"0 0 0 0"//nl//"0 0 0 0.001"//nl)
      call execute_command_line("rm -f "//prefix//".*")
      call run_femcod([string_type("run"), string_type("--lower"), string_type(path), string_type("-o"), &
         string_type(prefix), string_type("--maxcont"), string_type("3"), string_type("--quiet")], code)
      call check(error, code, 0, "run")
      if (allocated(error)) return
      text = read_text(prefix//".history.csv")
      ! The first contact closes at zero load; 2 nm pixels: an area of 4 nm^2 per contact.
      call check(error, contains_text(text, ",4,"), "area of one 2 nm pixel: "//text)
   end subroutine test_gwyddion_run

   subroutine test_height_unit(error)
      type(error_type), allocatable, intent(out) :: error
      type(height_map) :: map
      type(status_type) :: status
      character(len=:), allocatable :: path
      character(len=*), parameter :: nl = new_line("a")
      path = scratch_path("plain.txt")
      call write_text(path, "1 2"//nl//"3 4.5"//nl)
      call read_height_map(path, map, status, "A")
      call check(error, status%code == 0 .and. abs(map%z(2, 2) - 0.45_dp) < 1.0e-15_dp .and. map%unit == "A", &
         "angstrom to nm")
      if (allocated(error)) return
      call write_text(path, "# Value units: m"//nl//"1 2"//nl//"3 4"//nl)
      call read_height_map(path, map, status, "nm")
      call check(error, status%code == 3 .and. contains_text(status%message, "contradicts"), "conflict: "// &
         status%message)
      if (allocated(error)) return
      status = status_type()
      ! Heights of nanometres given in metres: a warning.
      call write_text(path, "1e-9 2e-9"//nl//"3e-9 4e-9"//nl)
      call read_height_map(path, map, status)
      call check(error, status%code == 0 .and. size(map%warnings) == 1, "a warning for metres")
      if (allocated(error)) return
      call check(error, contains_text(map%warnings(1)%s, "--height-unit m"), map%warnings(1)%s)
   end subroutine test_height_unit
   !> A 16 x 16 scan: a plane rising 0.5 nm per pixel (7.5 nm across) plus a checkerboard
   !> of +-0.05 nm (rms 0.05 nm about the plane, by construction). The rise is 150 times
   !> the roughness: femcod warns, with both figures; with --remove-plane it does not, and
   !> a scan of the checkerboard alone (no tilt) gives no warning either (issue 35).
   subroutine test_tilt_warning(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, tilted, flat, err
      character(len=16) :: buf
      integer :: i, j, code
      dir = scratch_path("tilt")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      tilted = ""
      flat = ""
      do i = 1, 16
         do j = 1, 16
            write(buf, '(f10.4)') 0.5_dp*(j - 1) + 0.05_dp*(-1)**(i + j)
            tilted = tilted//" "//trim(adjustl(buf))
            write(buf, '(f10.4)') 0.05_dp*(-1)**(i + j)
            flat = flat//" "//trim(adjustl(buf))
         end do
         tilted = tilted//new_line("a")
         flat = flat//new_line("a")
      end do
      call write_text(dir//"/tilted.txt", tilted)
      call write_text(dir//"/flat.txt", flat)
      call execute_command_line(self_command()//" run --lower "//dir//"/tilted.txt --pixel 1 --loads 1 -q -o "// &
         dir//"/a 2> "//dir//"/a.err", exitstat=code)
      err = read_text(dir//"/a.err")
      call check(error, code == 0 .and. contains_text(err, "plane rises 7.5 nm across the scan, 150 times the "// &
         "roughness about it (0.05 nm rms)"), "the tilt is reported: "//err)
      if (allocated(error)) return
      call execute_command_line(self_command()//" run --lower "//dir//"/tilted.txt --pixel 1 --loads 1 -q "// &
         "--remove-plane -o "//dir//"/b 2> "//dir//"/b.err", exitstat=code)
      call check(error, code == 0 .and. .not. contains_text(read_text(dir//"/b.err"), "plane rises"), &
         "--remove-plane: no warning: "//read_text(dir//"/b.err"))
      if (allocated(error)) return
      call execute_command_line(self_command()//" run --lower "//dir//"/flat.txt --pixel 1 --loads 1 -q -o "// &
         dir//"/c 2> "//dir//"/c.err", exitstat=code)
      call check(error, code == 0 .and. .not. contains_text(read_text(dir//"/c.err"), "plane rises"), &
         "no tilt: no warning: "//read_text(dir//"/c.err"))
   end subroutine test_tilt_warning
   !> `femcod mkdeck matrix --file F --pixel 2 --average 3` on a 6 x 6 matrix of heights
   !> h(i, j) = 10 i + j (nm): a 2 x 2 deck of 6 nm pixels, each the mean of its 3 x 3
   !> block, 10 (3 I - 1) + (3 J - 1) for block (I, J) (the mean of i is the block's middle
   !> row, by hand), less the smallest (mkdeck's rough surfaces start at 0): 0, 30, 3, 33
   !> as rows 1-2, columns 1-2. --average 4 on 6 x 6 is refused (exit 2), no deck written.
   subroutine test_average(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: dir, text
      character(len=8) :: buf
      integer :: i, j, code
      dir = scratch_path("average")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      text = ""
      do i = 1, 6
         do j = 1, 6
            write(buf, '(i0)') 10*i + j
            text = text//" "//trim(buf)
         end do
         text = text//new_line("a")
      end do
      call write_text(dir//"/h.txt", text)
      call run_femcod([string_type("mkdeck"), string_type("matrix"), string_type("--file"), &
         string_type(dir//"/h.txt"), string_type("--pixel"), string_type("2"), string_type("--average"), &
         string_type("3"), string_type("-o"), string_type(dir//"/a.deck")], code)
      call check(error, code, 0, "mkdeck matrix --average 3")
      if (allocated(error)) return
      call read_deck(dir//"/a.deck", deck, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, deck%np == 2 .and. deck%pixel == 6, "NP "//to_string(deck%np)//", pixel "// &
         to_string(deck%pixel)//"; expected 2 and 6 nm")
      if (allocated(error)) return
      ! mkdeck puts a height file's surface on the upper body (--shape-on upper).
      call check(error, all(abs(deck%upper - reshape([0.0_dp, 30.0_dp, 3.0_dp, 33.0_dp], [2, 2])) < 1.0e-12_dp), &
         "block means "//to_string(deck%upper(1, 1))//" "//to_string(deck%upper(2, 1))//" "// &
         to_string(deck%upper(1, 2))//" "//to_string(deck%upper(2, 2)))
      if (allocated(error)) return
      call run_femcod([string_type("mkdeck"), string_type("matrix"), string_type("--file"), &
         string_type(dir//"/h.txt"), string_type("--pixel"), string_type("2"), string_type("--average"), &
         string_type("4"), string_type("-o"), string_type(dir//"/b.deck")], code)
      call check(error, code, 2, "--average 4 of 6 x 6 heights")
      if (allocated(error)) return
      call check(error, .not. file_exists(dir//"/b.deck"), "a refused --average wrote a deck")
   end subroutine test_average
end module test_heights
