!> What the study commands (femcod_resolution_command, femcod_summits_command,
!> femcod_multiscale_command, femcod_refine_command) share: the options of the surface
!> studies, the scene or heights a study reads, its outputs checked before the input is
!> read, and the power-law figures.
module femcod_studies
   use, intrinsic :: iso_fortran_env, only: error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_BAD_INPUT, STATUS_IO
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str, sig_str, parse_real, json_string, json_number, split_list
   use femcod_about, only: FEMCOD_VERSION
   use femcod_generate, only: scene_spec
   use femcod_heights, only: load_scene, read_height_map, height_map, is_height_file, height_file_path, &
      looks_like_height_matrix
   use femcod_files, only: default_prefix, file_part
   use femcod_output_guard, only: guard_outputs, OUTPUT_RESULT
   use femcod_svg, only: svg_series, svg_multi_plot, add_series
   use femcod_scene, only: flip_upper
   use femcod_surfaces, only: remove_plane
   use femcod_richardson, only: power_law_fit
   use femcod_help, only: help_requested
   use femcod_options, only: option_spec, parsed_options, parse_options, flag_option, real_option, integer_option, &
      text_option, choice_option, real_list_option, integer_list_option, get_option, option_given
   implicit none
   private
   public :: surface_options, summit_plot, fitted_exponent, surface_scene, study_deck, check_outputs, study_heights, &
      surface_table, parse_surface_options, fail_with, study_json, command_text

   !> Options shared by `summits` and `multiscale`.
   type :: surface_options
      character(len=:), allocatable :: input, prefix, height_unit
      real(dp) :: pixel = 0
      logical :: plane = .false., force = .false., quiet = .false.
      integer, allocatable :: sizes(:)
   end type surface_options

contains

   !> One of the Fig. 3.2 panels: a summit statistic against the box size, log-log,
   !> with its fitted power law dashed.
   function summit_plot(title, ylabel, box, values, exponent, prefactor) result(svg)
      character(len=*), intent(in) :: title, ylabel
      real(dp), intent(in) :: box(:), values(:), exponent, prefactor
      character(len=:), allocatable :: svg
      type(svg_series), allocatable :: series(:)
      call add_series(series, "summits", box, values)
      call add_series(series, "fit: d^"//sig_str(exponent, 3), box, fit_line(prefactor, exponent, box), dashed=.true., &
         markers=.false.)
      svg = svg_multi_plot(title, "box size d (nm)", ylabel, series, .true., .true.)
   end function summit_plot

   !> The fitted power law at the points, or nothing when the fit failed (fewer than
   !> two positive values).
   function fit_line(prefactor, exponent, x) result(y)
      real(dp), intent(in) :: prefactor, exponent, x(:)
      real(dp), allocatable :: y(:)
      if (prefactor > 0) then
         y = prefactor*x**exponent
      else
         y = 0*x
      end if
   end function fit_line

   !> Exponent of the least-squares power law through the positive points.
   function fitted_exponent(x, y) result(e)
      real(dp), intent(in) :: x(:), y(:)
      real(dp) :: e, pre
      logical, allocatable :: keep(:)
      keep = x > 0 .and. y > 0
      call power_law_fit(pack(x, keep), pack(y, keep), e, pre)
   end function fitted_exponent

   !> The scene of a height file for a study: the heights on an elastic lower body
   !> (--young, --poisson; default 200 GPa, 0.25) against a rigid flat, as `run --lower`.
   subroutine surface_scene(parsed, input, spec)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: input
      type(scene_spec), intent(out) :: spec
      character(len=:), allocatable :: text
      spec%kind = "matrix"
      spec%label = "heights from "//input
      call get_option(parsed, "--label", spec%label)
      spec%matrix_file = input
      spec%second_file = ""
      spec%shape_on = "lower"
      call get_option(parsed, "--pixel", spec%pixel)
      call get_option(parsed, "--young", spec%young)
      call get_option(parsed, "--poisson", spec%poisson)
      call get_option(parsed, "--maxcont", spec%maxcont)
      call get_option(parsed, "--remove-plane", spec%plane)
      call get_option(parsed, "--rigid-factor", spec%rigid_factor)
      if (option_given(parsed, "--height-unit")) then
         text = ""
         call get_option(parsed, "--height-unit", text)
         spec%height_unit = text
      end if
      text = ""
      call get_option(parsed, "--rigid", text)
      if (text /= "") spec%rigid = text
   end subroutine surface_scene

   !> The problem of a study: a deck, or (a spec with a pixel size) a height file.
   subroutine study_deck(input, spec, deck, status)
      character(len=*), intent(in) :: input
      type(scene_spec), intent(in) :: spec
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      if (spec%pixel > 0 .or. is_height_file(input)) then
         call load_scene(spec, deck, status)
      else
         call read_deck(input, deck, status)
         if (status%code /= 0 .and. looks_like_height_matrix(input)) then
            status%code = STATUS_USAGE
            status%message = input//" reads as a matrix of heights, not as a deck: give --pixel D (nm) to study "// &
               "it as heights ("//status%message//")"
         end if
      end if
   end subroutine study_deck

   !> Before any work: no output names the input `input` (exit 2), an existing output is
   !> replaced only with --force and only when femcod wrote it (exit 5; see
   !> io/femcod_output_guard), and the directory takes files.
   subroutine check_outputs(names, input, force, status)
      type(string_type), intent(in) :: names(:)
      character(len=*), intent(in) :: input
      logical, intent(in) :: force
      type(status_type), intent(inout) :: status
      integer :: unit, ios
      type(string_type) :: inputs(1)
      inputs(1)%s = height_file_path(input)
      call guard_outputs(names, inputs, force, OUTPUT_RESULT, status)
      if (status%code /= 0) return
      open(newunit=unit, file=names(1)%s//".part", status="replace", action="write", iostat=ios)
      if (ios /= 0) then
         call set_error(status, STATUS_IO, names(1)%s//": cannot write (directory missing or not writable); nothing was run")
         return
      end if
      close(unit, status="delete")
   end subroutine check_outputs

   !> Heights for the surface studies: a height file (with --pixel) or a deck, whose
   !> composite roughness (lower surface plus the upper as it faces it) is analysed.
   subroutine study_heights(input, pixel, plane, z, d, status, height_unit, estar)
      character(len=*), intent(in) :: input
      real(dp), intent(in) :: pixel
      logical, intent(in) :: plane
      real(dp), allocatable, intent(out) :: z(:, :)
      real(dp), intent(out) :: d
      type(status_type), intent(inout) :: status
      character(len=*), intent(in) :: height_unit
      !> A deck's composite (Hertz) modulus E* (GPa), 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2;
      !> 0 for a height file, which gives no material.
      real(dp), intent(out), optional :: estar
      type(contact_problem) :: deck
      type(height_map) :: map
      integer :: k
      if (present(estar)) estar = 0
      if (pixel > 0 .or. is_height_file(input)) then
         call read_height_map(input, map, status, height_unit)
         if (status%code /= 0) return
         do k = 1, size(map%warnings)
            write(error_unit, '(a)') "femcod: warning: "//map%warnings(k)%s
         end do
         d = pixel
         if (.not. d > 0) d = map%pixel_x
         if (.not. d > 0) then
            call set_error(status, STATUS_USAGE, input//" does not give its pixel size: give --pixel D (nm)")
            return
         end if
         call move_alloc(map%z, z)
      else
         call read_deck(input, deck, status)
         if (status%code /= 0 .and. looks_like_height_matrix(input)) then
            status%code = STATUS_USAGE
            status%message = input//" reads as a matrix of heights, not as a deck: give --pixel D (nm) to study "// &
               "it as heights ("//status%message//")"
         end if
         if (status%code /= 0) return
         z = deck%lower + flip_upper(deck%upper)
         d = deck%pixel
         if (present(estar)) estar = 1/((1 - deck%poisson(1)**2)/deck%young(1) + (1 - deck%poisson(2)**2)/deck%young(2))
      end if
      if (status%code /= 0) return
      if (size(z, 1) /= size(z, 2)) then
         call set_error(status, STATUS_BAD_INPUT, input//": expected a square matrix of heights, found "// &
            int_str(size(z, 1))//" rows of "//int_str(size(z, 2))//" values")
         return
      end if
      if (size(z, 1) < 5) then
         call set_error(status, STATUS_BAD_INPUT, input//": expected at least 5 x 5 heights for a surface study, found "// &
            int_str(size(z, 1))//" x "//int_str(size(z, 2)))
         return
      end if
      if (plane) call remove_plane(z)
   end subroutine study_heights

   !> The options of `summits` (command "summits") and `multiscale` (its own besides).
   function surface_table(command) result(table)
      character(len=*), intent(in) :: command
      type(option_spec), allocatable :: table(:)
      table = [ &
         text_option("--output", "PREFIX", "output prefix (default: the input's name)", alias="-o"), &
         real_option("--pixel", "D", "pixel size in nm: FILE holds heights (nm), not a deck", lower=0.0_dp, &
            closed="()"), &
         integer_list_option("--sizes", "n1,...", "neighbourhood sizes (default 1, 2, 3, 4, 6, 8, 11, 16, ... up "// &
            "to N/8)", lower=1), &
         flag_option("--remove-plane", "subtract the least-squares plane"), &
         choice_option("--height-unit", "m|mm|um|nm|A|pm", "unit of the heights in files that do not state theirs "// &
            "(default nm)"), &
         flag_option("--force", "replace existing result files"), &
         flag_option("--quiet", "no summary", alias="-q")]
      if (command /= "multiscale") return
      table = [table, &
         integer_option("--template-size", "n", "neighbourhood size of the template (default: the size whose "// &
            "summit count is nearest 100, as the thesis' template)", lower=1), &
         real_list_option("--s", "s1,...", "length scaling constants (default 2.5,5,10)", lower=1.0_dp, closed="()"), &
         real_option("--min-length", "L", "finest length scale in nm (default 4: ten atomic spacings, the limit of "// &
            "the elastic solution)", lower=0.0_dp, closed="()"), &
         integer_option("--scales", "K", "the number of scales instead of --min-length", lower=1, upper=60), &
         real_option("--load", "F", "total load in nN (default 1e6, 1 mN)", lower=0.0_dp, closed="()"), &
         real_option("--estar", "E", "composite modulus in GPa for a height file (default 200); a deck gives "// &
            "its own: 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2", lower=0.0_dp, closed="()"), &
         real_list_option("--exponents", "eh,eR,eN", "override the power laws of the summit search", length=3)]
   end function surface_table

   !> Parse the options of `summits` and `multiscale` (`code` -1: help asked).
   subroutine parse_surface_options(command, args, opts, parsed, code)
      character(len=*), intent(in) :: command
      type(string_type), intent(in) :: args(:)
      type(surface_options), intent(out) :: opts
      type(parsed_options), intent(out) :: parsed
      integer, intent(out) :: code
      type(status_type) :: status
      integer :: k
      code = 0
      if (help_requested(args)) then
         code = -1
         return
      end if
      opts%input = ""
      opts%prefix = ""
      opts%height_unit = ""
      allocate(opts%sizes(0))
      call parse_options(surface_table(command), args, parsed, status)
      if (status%code == 0) then
         if (size(parsed%positional) == 0) call set_error(status, STATUS_USAGE, "no deck or height file given")
         if (size(parsed%positional) > 1) call set_error(status, STATUS_USAGE, "one input only (found '"// &
            parsed%positional(1)%s//"' and '"//parsed%positional(2)%s//"')")
      end if
      if (status%code /= 0) then
         call usage_line(command, status%message)
         code = status%code
         return
      end if
      opts%input = parsed%positional(1)%s
      call get_option(parsed, "--output", opts%prefix)
      call get_option(parsed, "--pixel", opts%pixel)
      call get_option(parsed, "--sizes", opts%sizes)
      call get_option(parsed, "--remove-plane", opts%plane)
      call get_option(parsed, "--height-unit", opts%height_unit)
      call get_option(parsed, "--force", opts%force)
      call get_option(parsed, "--quiet", opts%quiet)
      if (opts%prefix == "") opts%prefix = default_prefix(file_part(opts%input))
      ! An option the run would ignore is refused, as run does.
      do k = 1, size(opts%sizes)
         if (count(opts%sizes == opts%sizes(k)) > 1) then
            call set_error(status, STATUS_USAGE, "--sizes: "//int_str(opts%sizes(k))//" is given twice")
            exit
         end if
      end do
      if (status%code == 0 .and. opts%height_unit /= "" .and. .not. (opts%pixel > 0 .or. &
         is_height_file(opts%input))) call set_error(status, STATUS_USAGE, "--height-unit: "//opts%input// &
         " is a deck, whose heights are in nm; the unit is for height files")
      if (status%code == 0 .and. option_given(parsed, "--min-length") .and. option_given(parsed, "--scales")) &
         call set_error(status, STATUS_USAGE, "give --min-length L or --scales K, not both (the scales are K, "// &
            "or as many as reach L)")
      if (status%code /= 0) then
         call usage_line(command, status%message)
         code = status%code
      end if
   end subroutine parse_surface_options

   subroutine usage_line(command, message)
      character(len=*), intent(in) :: command, message
      write(error_unit, '(a)') "femcod "//command//": "//message//" (femcod "//command//" --help)"
   end subroutine usage_line

   subroutine fail_with(command, status, code)
      character(len=*), intent(in) :: command
      type(status_type), intent(in) :: status
      integer, intent(out) :: code
      write(error_unit, '(a)') "femcod "//command//": "//status%message
      code = status%code
   end subroutine fail_with

   !> A study's tables as one JSON file (PREFIX.<command>.json): the program, the command
   !> line, the input, and each CSV file of the set (names(k) ending in .csv, its text
   !> texts(k)) as a list of rows keyed by its columns, whose names carry the units,
   !> under the file's name between PREFIX. and .csv: numbers as numbers (nan and empty
   !> fields null), other fields as strings. Made from the tables' own text, it says what
   !> they say.
   function study_json(command, args, input, prefix, names, texts) result(j)
      character(len=*), intent(in) :: command, input, prefix
      type(string_type), intent(in) :: args(:), names(:), texts(:)
      character(len=:), allocatable :: j, line, tables
      character(len=1), parameter :: nl = new_line("a")
      integer :: k, n
      line = command_text(command, args)
      tables = ""
      do k = 1, size(names)
         n = len(names(k)%s)
         if (n < 5 .or. k > size(texts)) cycle
         if (names(k)%s(n - 3:) /= ".csv") cycle
         if (len(tables) > 0) tables = tables//","//nl
         tables = tables//'    '//json_string(names(k)%s(len(prefix) + 2:n - 4))//': '//csv_json(texts(k)%s)
      end do
      j = '{'//nl//'  "femcod_version": '//json_string(FEMCOD_VERSION)//','//nl//'  "command": '// &
         json_string(command)//', "command_line": '//json_string(line)//','//nl//'  "input": '// &
         json_string(input)//','//nl//'  "tables": {'//nl//tables//nl//'  }'//nl//'}'//nl
   end function study_json

   !> The command as typed: "femcod COMMAND ARG ...".
   function command_text(command, args) result(line)
      character(len=*), intent(in) :: command
      type(string_type), intent(in) :: args(:)
      character(len=:), allocatable :: line
      integer :: k
      line = "femcod "//command
      do k = 1, size(args)
         line = line//" "//args(k)%s
      end do
   end function command_text

   !> A CSV text (a header line, then rows) as a JSON list of objects, one per row.
   function csv_json(text) result(j)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: j
      type(string_type), allocatable :: header(:), cells(:)
      integer :: a, b, c
      j = '['
      a = 1
      b = index(text, new_line("a"))
      if (b == 0) b = len(text) + 1
      header = split_list(text(a:b - 1))
      a = b + 1
      do while (a <= len(text))
         b = index(text(a:), new_line("a"))
         if (b == 0) b = len(text) - a + 2
         cells = split_list(text(a:a + b - 2))
         a = a + b
         j = j//trim(merge(", ", "  ", len(j) > 1))//'{'
         do c = 1, min(size(header), size(cells))
            j = j//trim(merge(", ", "  ", c > 1))//json_string(header(c)%s)//': '//json_value(cells(c)%s)
         end do
         j = trim(j)//'}'
      end do
      j = j//']'
   contains
      function json_value(cell) result(v)
         character(len=*), intent(in) :: cell
         character(len=:), allocatable :: v
         real(dp) :: x
         logical :: ok
         if (len_trim(cell) == 0) then
            v = "null"
            return
         end if
         call parse_real(trim(cell), x, ok)
         if (ok) then
            v = json_number(x)
         else
            v = json_string(cell)
         end if
      end function json_value
   end function csv_json
end module femcod_studies

