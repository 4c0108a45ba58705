!> The femcod command line. `femcod_command` reads the process arguments;
!> `run_femcod` takes them as a list, so tests drive the same code path. Returns the
!> exit code: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O. Every command
!> parses its arguments against its option table (cli/femcod_options).
module femcod_cli
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp, i8
   use femcod_memory, only: memory_setting, MEMORY_VARIABLE
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_strings, only: string_type, int_str, parse_integer, append_string
   use femcod_problem, only: contact_problem
   use femcod_deck, only: write_deck, read_deck
   use femcod_workspace, only: workspace_type, workspace_layout, workspace_table, MAX_WORKSPACE_CONTACTS
   use femcod_problem, only: MAX_NP
   use femcod_generate, only: scene_spec, build_problem, verification_spec, VERIFICATION_DECKS, KINDS, check_scene_spec
   use femcod_heights, only: load_scene, height_file_path
   use femcod_output_guard, only: guard_outputs, OUTPUT_DECK, OUTPUT_RESULT
   use femcod_run, only: run_command
   use femcod_process, only: SIGINT, SIGTERM, SIGUSR1
   use femcod_resolution_command, only: resolution_command
   use femcod_summits_command, only: summits_command
   use femcod_multiscale_command, only: multiscale_command
   use femcod_refine_command, only: refine_command
   use femcod_report_command, only: report_command
   use femcod_about, only: FEMCOD_VERSION
   use femcod_verification, only: write_verification_report
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, scene_options, flag_option, &
      real_option, integer_option, text_option, choice_option, get_option, option_given, refuse_options
   implicit none
   private
   public :: femcod_command, run_femcod, command_arguments, mkdeck_table, parse_mkdeck_arguments, FEMCOD_VERSION

contains

   !> Entry point for app/main.f90.
   subroutine femcod_command(code)
      integer, intent(out) :: code
      call run_femcod(command_arguments(), code)
   end subroutine femcod_command

   !> The process arguments as a list.
   function command_arguments() result(args)
      type(string_type), allocatable :: args(:)
      integer :: i, n, length
      n = command_argument_count()
      allocate(args(n))
      do i = 1, n
         call get_command_argument(i, length=length)
         allocate(character(len=length) :: args(i)%s)
         call get_command_argument(i, args(i)%s)
      end do
   end function command_arguments

   !> Dispatch on the first argument.
   subroutine run_femcod(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer(i8) :: cap
      character(len=64) :: setting
      code = 0
      if (size(args) == 0) then
         call usage_error("no command given")
         code = STATUS_USAGE
         return
      end if
      ! A memory cap that does not read is refused before any work, not ignored.
      call memory_setting(cap)
      if (cap < 0) then
         call get_environment_variable(MEMORY_VARIABLE, setting)
         call usage_error(MEMORY_VARIABLE//": expected a number of bytes, optionally with K, M, G or T "// &
            "(KiB to TiB), for example 8G, found '"//trim(setting)//"'")
         code = STATUS_USAGE
         return
      end if
      select case (args(1)%s)
      case ("-h", "--help", "help")
         call print_help()
      case ("-V", "--version", "version")
         write(output_unit, '(a)') "femcod "//FEMCOD_VERSION
      case ("workspace")
         call workspace_command(args(2:), code)
      case ("mkdeck")
         call mkdeck_command(args(2:), code)
      case ("run")
         call run_command(args(2:), code)
      case ("resolution")
         call resolution_command(args(2:), code)
      case ("summits")
         call summits_command(args(2:), code)
      case ("multiscale")
         call multiscale_command(args(2:), code)
      case ("refine")
         call refine_command(args(2:), code)
      case ("report")
         call report_command(args(2:), code)
      case ("verify")
         call verify_command(args(2:), code)
      case default
         call usage_error("unknown command '"//args(1)%s//"'")
         code = STATUS_USAGE
      end select
   end subroutine run_femcod

   subroutine print_help()
      write(output_unit, '(a)') &
         "femcod "//FEMCOD_VERSION//": Boussinesq finite-element contact of rough surfaces (Bora 2012)", &
         "", &
         "usage: femcod <command> [options]", &
         "", &
         "commands:", &
         "  run DECK [options]        contact history of a deck (femcod run --help)", &
         "  mkdeck KIND [options]     generate a deck (femcod mkdeck --help)", &
         "  resolution DECK [options] the resolution study of section 4.5 (femcod resolution --help)", &
         "  summits FILE [options]    summit search, PSD and structure function of chapter 3", &
         "  multiscale FILE [options] the multiscale Hertz model of section 3.3", &
         "  refine DECK --loads ...   the contact area below the pixel: the thesis' third model (section 5.3)", &
         "  report PREFIX|DIR         one self-contained HTML page of results (femcod report --help)", &
         "  workspace NP MAXCONT      print the Appendix B memory map (Tables B.1, B.2)", &
         "  verify [-o FILE]          recompute the thesis checks, write doc/verification.md", &
         "  bench [--full]            speed against error, one table (use the release build)", &
         "  --help, --version", &
         "", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure or not enough memory, 5 I/O,", &
         "  128 + N after signal N: "//int_str(128 + SIGTERM)//" SIGTERM, "//int_str(128 + SIGINT)//" SIGINT, "// &
         int_str(128 + SIGUSR1)//" SIGUSR1 (a checkpoint is kept where the", &
         "  solver writes one; continue with --restart)", &
         "", &
         "environment: FEMCOD_MEMORY=8G caps the memory femcod may use (bytes, or K, M, G, T), below the", &
         "  machine's and the job's (cgroup) limits; every solver and study checks its estimate against", &
         "  it before the work (exit 4)"
   end subroutine print_help

   subroutine usage_error(message)
      character(len=*), intent(in) :: message
      write(error_unit, '(a)') "femcod: "//message//" (femcod --help)"
   end subroutine usage_error

   !> A command's usage error on standard error, and its exit code.
   subroutine command_usage(command, status, code)
      character(len=*), intent(in) :: command
      type(status_type), intent(in) :: status
      integer, intent(out) :: code
      write(error_unit, '(a)') "femcod "//command//": "//status%message//" (femcod "//command//" --help)"
      code = status%code
   end subroutine command_usage



   !> `femcod workspace NP MAXCONT`: one line per block, then the totals.
   subroutine workspace_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(workspace_type) :: ws
      type(status_type) :: status
      type(parsed_options) :: parsed
      integer :: np, maxcont, k
      logical :: ok1, ok2
      character(len=120), allocatable :: lines(:)
      code = 0
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod workspace NP MAXCONT", &
            "Prints the memory map of the integer and real work arrays of Appendix B (Tables B.1, B.2):", &
            "block name, first address, size in words, contents; then IPEND, MPEND and the bytes they need.", &
            "MAXNODE = 4*MAXCONT+2; MPSTIF is femcod's skyline size (7*MAXCONT+2)*(MAXCONT+1)/2 (doc/workspace.md)."
         return
      end if
      call parse_options([option_spec ::], args, parsed, status)
      if (status%code == 0 .and. size(parsed%positional) /= 2) &
         call set_error(status, STATUS_USAGE, "workspace takes NP and MAXCONT")
      if (status%code == 0) then
         call parse_integer(parsed%positional(1)%s, np, ok1)
         call parse_integer(parsed%positional(2)%s, maxcont, ok2)
         if (.not. (ok1 .and. ok2)) then
            call set_error(status, STATUS_USAGE, "NP and MAXCONT must be integers")
         else if (np < 1 .or. np > MAX_NP) then
            call set_error(status, STATUS_USAGE, "NP "//int_str(np)//": expected 1 to "//int_str(MAX_NP)// &
               " (the largest grid a deck may hold)")
         else if (maxcont < 1 .or. int(maxcont, i8) > int(np, i8)**2 .or. maxcont > MAX_WORKSPACE_CONTACTS) then
            if (int(np, i8)**2 <= MAX_WORKSPACE_CONTACTS) then
               call set_error(status, STATUS_USAGE, "MAXCONT "//int_str(maxcont)//": expected 1 to NP^2 = "// &
                  int_str(int(np, i8)**2))
            else
               call set_error(status, STATUS_USAGE, "MAXCONT "//int_str(maxcont)//": expected 1 to "// &
                  int_str(MAX_WORKSPACE_CONTACTS)//", where MAXNODE = 4 MAXCONT + 2 still fits an integer word "// &
                  "(below NP^2 = "//int_str(int(np, i8)**2)//")")
            end if
         end if
      end if
      if (status%code /= 0) then
         call command_usage("workspace", status, code)
         return
      end if
      call workspace_layout(np, maxcont, ws, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod: "//status%message
         code = status%code
         return
      end if
      lines = workspace_table(ws)
      do k = 1, size(lines)
         write(output_unit, '(a)') trim(lines(k))
      end do
   end subroutine workspace_command

   !> The options of `femcod mkdeck`; the mode of a kind's own options is the kind.
   function mkdeck_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [ &
         text_option("--output", "FILE", "output deck (written atomically; FILE.h5: an HDF5 deck)", alias="-o"), &
         flag_option("--force", "replace an existing deck (only a deck; never the --file it is made from)"), &
         text_option("--verification", "NAME|all", "a verification deck of input/ by name, or all of them", &
            mode="verification"), &
         text_option("--dir", "DIR", "directory of the verification decks (default input/ for all, else .)", &
            mode="verification"), &
         integer_option("--np", "N", "pixels per side", lower=1, mode="circle-punch|square-punch|sphere|flat|sinusoid|"// &
            "wm|self-affine"), &
         choice_option("--shape-on", "upper|lower", "surface that carries the shape (default upper)", mode="kind"), &
         scene_options("kind"), &
         real_option("--radius", "R", "punch or sphere radius in nm", lower=0.0_dp, closed="()", &
            mode="circle-punch|sphere"), &
         real_option("--area", "A", "punch area in nm^2 (default pi R^2)", lower=0.0_dp, closed="()", &
            mode="circle-punch"), &
         real_option("--height", "H", "punch or flat height in nm (default: R for the circle, NP d/3 for the "// &
            "square, 0 for a flat)", mode="circle-punch|square-punch|flat"), &
         real_option("--amplitude", "A", "sinusoid amplitude in nm (default 1)", mode="sinusoid"), &
         real_option("--scale", "W", "sinusoid length scale w in nm (default 10)", lower=0.0_dp, closed="()", &
            mode="sinusoid"), &
         real_option("--ds", "D", "fractal dimension of the surface (default 2.4)", lower=2.0_dp, upper=3.0_dp, &
            closed="()", mode="wm"), &
         real_option("--g", "G", "fractal roughness in nm (default 1.36e-2)", lower=0.0_dp, closed="()", mode="wm"), &
         real_option("--gamma", "GAMMA", "frequency density (default 1.5)", lower=1.0_dp, closed="()", mode="wm"), &
         real_option("--lmax", "L", "largest wavelength in nm (default 1000)", lower=0.0_dp, closed="()", mode="wm"), &
         real_option("--lmin", "L", "smallest wavelength in nm (default 1)", lower=0.0_dp, closed="()", mode="wm"), &
         integer_option("--ridges", "M", "number of ridges (default 10)", lower=1, mode="wm"), &
         integer_option("--seed", "S", "random seed (default 1)", mode="wm|self-affine"), &
         real_option("--hurst", "H", "Hurst exponent (default 0.8)", lower=0.0_dp, upper=1.0_dp, closed="(]", &
            mode="self-affine"), &
         real_option("--rms", "S", "rms height in nm (default 1)", lower=0.0_dp, closed="()", mode="self-affine"), &
         text_option("--file", "FILE", "heights: an ASCII matrix (one row per line, '#' comments, Gwyddion export) "// &
            "or FILE.h5:/dataset (square, C order)", mode="matrix"), &
         integer_option("--average", "N", "average N x N blocks of heights into one pixel, as a tip N pixels wide "// &
            "sees them (section 4.5): NP/N pixels of N times the size (default 1: none)", lower=1, mode="matrix")]
   end function mkdeck_table

   subroutine mkdeck_help()
      write(output_unit, '(a)') &
         "usage: femcod mkdeck KIND -o FILE [--force] [options]", &
         "       femcod mkdeck --verification NAME|all [-o FILE | --dir DIR] [--force]", &
         "       femcod mkdeck convert IN OUT [--force]", &
         "", &
         "Writes an input deck (doc/deck-format.md): a text deck, or an HDF5 deck when FILE ends in .h5", &
         "(the same content as datasets, read at disk speed; `convert` turns one form into the other).", &
         "The shape goes on one surface, the other is flat;", &
         "a rigid body gets E --rigid-factor times the elastic one (default 1e10), and so do the", &
         "contact/interface elements (thesis section 4.4 uses 1e5, as the decks of input/ do).", &
         "", &
         "kinds:", &
         "  circle-punch  flat circular punch: the round(area/d^2) pixels nearest the centre pixel (NP odd)", &
         "  square-punch  central NP/3 x NP/3 pixels (NP divisible by 3)", &
         "  sphere        z = sqrt(R^2 - r^2) inside r < R, 0 outside", &
         "  flat          constant height", &
         "  sinusoid      eq. 3.3: z = A cos(x/w) cos(y/w)", &
         "  wm            Weierstrass-Mandelbrot eq. 3.6", &
         "  self-affine   Gaussian random surface by FFT filtering, C(q) ~ q^-2(1+H) from 2pi/L to pi/d", &
         "  matrix        heights from --file", &
         "", "options:"
      call print_lines(option_help(mkdeck_table(), ""))
      call print_lines(option_help(mkdeck_table(), "kind"))
      call print_lines(option_help(mkdeck_table(), "circle-punch|square-punch|sphere|flat|sinusoid|wm|self-affine"))
      write(output_unit, '(a)') "", "options of one or some kinds (refused with the others):"
      call print_lines(option_help(mkdeck_table(), "circle-punch|sphere"))
      call print_lines(option_help(mkdeck_table(), "circle-punch"))
      call print_lines(option_help(mkdeck_table(), "circle-punch|square-punch|flat"))
      call print_lines(option_help(mkdeck_table(), "sinusoid"))
      call print_lines(option_help(mkdeck_table(), "wm"))
      call print_lines(option_help(mkdeck_table(), "wm|self-affine"))
      call print_lines(option_help(mkdeck_table(), "self-affine"))
      call print_lines(option_help(mkdeck_table(), "matrix"))
      write(output_unit, '(a)') "", "verification decks:"
      call print_lines(option_help(mkdeck_table(), "verification"))
      write(output_unit, '(a)') "  names: circle_punch_d1 d3 d9 (Table 4.1), square_punch_n1 n3 n9 n27 (Table 4.2),", &
         "  sphere_d4 d2 d1 d05 (Figs. 4.14-4.16), rough_selfaffine_32."
   end subroutine mkdeck_help

   !> The arguments of `femcod mkdeck` as a scene spec (or a verification request): no I/O.
   subroutine parse_mkdeck_arguments(args, spec, output, verification, dir, status, force)
      type(string_type), intent(in) :: args(:)
      type(scene_spec), intent(out) :: spec
      character(len=:), allocatable, intent(out) :: output, verification, dir
      type(status_type), intent(inout) :: status
      !> --force: an existing deck may be replaced.
      logical, intent(out), optional :: force
      type(parsed_options) :: parsed
      character(len=:), allocatable :: text
      output = ""
      verification = ""
      dir = ""
      spec%kind = ""
      spec%label = ""
      spec%matrix_file = ""
      if (present(force)) force = .false.
      call parse_options(mkdeck_table(), args, parsed, status)
      if (status%code /= 0) return
      if (present(force)) call get_option(parsed, "--force", force)
      call get_option(parsed, "--output", output)
      call get_option(parsed, "--verification", verification)
      call get_option(parsed, "--dir", dir)
      if (size(parsed%positional) > 1) then
         call set_error(status, STATUS_USAGE, "one KIND only, found '"//parsed%positional(2)%s//"'")
         return
      end if
      if (size(parsed%positional) == 1) spec%kind = parsed%positional(1)%s
      if (verification /= "") then
         if (spec%kind /= "") then
            call set_error(status, STATUS_USAGE, "give a KIND or --verification, not both")
            return
         end if
         call refuse_options(parsed, "verification", "", status)
         if (status%code == 0 .and. verification /= "all" .and. .not. any(VERIFICATION_DECKS == verification)) &
            call set_error(status, STATUS_USAGE, "--verification: no deck named '"//verification//"' (names: "// &
               comma_list(VERIFICATION_DECKS)//", or all)")
         return
      end if
      if (spec%kind == "") then
         call set_error(status, STATUS_USAGE, "no KIND given (one of: "//comma_list(KINDS)//")")
         return
      end if
      if (.not. any(KINDS == spec%kind)) then
         call set_error(status, STATUS_USAGE, "unknown KIND '"//spec%kind//"' (one of: "//comma_list(KINDS)//")")
         return
      end if
      call refuse_options(parsed, "kind|"//spec%kind, "verification=to --verification", status)
      if (status%code /= 0) return
      if (output == "") then
         call set_error(status, STATUS_USAGE, "-o FILE is required")
         return
      end if
      call get_option(parsed, "--label", spec%label)
      call get_option(parsed, "--file", spec%matrix_file)
      call get_option(parsed, "--average", spec%average)
      text = ""
      call get_option(parsed, "--shape-on", text)
      if (text /= "") spec%shape_on = text
      text = ""
      call get_option(parsed, "--rigid", text)
      if (text /= "") spec%rigid = text
      call get_option(parsed, "--remove-plane", spec%plane)
      text = ""
      call get_option(parsed, "--height-unit", text)
      if (text /= "") spec%height_unit = text
      call get_option(parsed, "--np", spec%np)
      call get_option(parsed, "--maxcont", spec%maxcont)
      call get_option(parsed, "--seed", spec%seed)
      call get_option(parsed, "--ridges", spec%ridges)
      call get_option(parsed, "--pixel", spec%pixel)
      call get_option(parsed, "--young", spec%young)
      call get_option(parsed, "--poisson", spec%poisson)
      call get_option(parsed, "--rigid-factor", spec%rigid_factor)
      call get_option(parsed, "--radius", spec%radius)
      call get_option(parsed, "--area", spec%area)
      call get_option(parsed, "--height", spec%height)
      call get_option(parsed, "--hurst", spec%hurst)
      call get_option(parsed, "--rms", spec%rms)
      call get_option(parsed, "--amplitude", spec%amplitude)
      call get_option(parsed, "--scale", spec%scale)
      call get_option(parsed, "--ds", spec%ds)
      call get_option(parsed, "--g", spec%g)
      call get_option(parsed, "--gamma", spec%gamma)
      call get_option(parsed, "--lmax", spec%lmax)
      call get_option(parsed, "--lmin", spec%lmin)
      call check_scene_spec(spec, status)
      if (spec%label == "") spec%label = "femcod mkdeck "//spec%kind
   end subroutine parse_mkdeck_arguments

   !> `femcod mkdeck`.
   subroutine mkdeck_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: output, verification, dir
      type(string_type), allocatable :: outputs(:), inputs(:)
      logical :: force
      integer :: k
      code = 0
      if (help_requested(args)) then
         call mkdeck_help()
         return
      end if
      if (size(args) > 0) then
         if (args(1)%s == "convert") then
            call convert_deck_command(args(2:), code)
            return
         end if
      end if
      call parse_mkdeck_arguments(args, spec, output, verification, dir, status, force)
      if (status%code /= 0) then
         call command_usage("mkdeck", status, code)
         return
      end if
      ! Every deck this command writes is checked before the first is made.
      allocate(outputs(0), inputs(0))
      if (verification == "all") then
         if (dir == "") dir = "input"
         do k = 1, size(VERIFICATION_DECKS)
            call append_string(outputs, dir//"/"//trim(VERIFICATION_DECKS(k))//".deck")
         end do
      else if (verification /= "") then
         if (output == "") then
            if (dir == "") dir = "."
            output = dir//"/"//verification//".deck"
         end if
         call append_string(outputs, output)
      else
         call append_string(outputs, output)
         if (spec%matrix_file /= "") call append_string(inputs, height_file_path(spec%matrix_file))
      end if
      call guard_outputs(outputs, inputs, force, OUTPUT_DECK, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod mkdeck: "//status%message
         code = status%code
         return
      end if
      if (verification /= "") then
         if (verification == "all") then
            do k = 1, size(VERIFICATION_DECKS)
               call one_verification(trim(VERIFICATION_DECKS(k)), dir//"/"//trim(VERIFICATION_DECKS(k))//".deck")
               if (code /= 0) return
            end do
         else
            call one_verification(verification, output)
         end if
         return
      end if
      call load_scene(spec, deck, status)
      if (status%code == 0) call write_deck(output, deck, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod: "//status%message
         code = status%code
         return
      end if
      write(output_unit, '(a)') "wrote "//output//" (NP = "//int_str(deck%np)//", MAXCONT = "// &
         int_str(deck%maxcont)//")"
   contains
      subroutine one_verification(name, path)
         character(len=*), intent(in) :: name, path
         type(scene_spec) :: vspec
         call verification_spec(name, vspec, status)
         if (status%code == 0) call build_problem(vspec, deck, status)
         if (status%code == 0) call write_deck(path, deck, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod: "//status%message
            code = status%code
            return
         end if
         write(output_unit, '(a)') "wrote "//path//" (NP = "//int_str(deck%np)//", MAXCONT = "// &
            int_str(deck%maxcont)//")"
      end subroutine one_verification
   end subroutine mkdeck_command

   !> `femcod mkdeck convert IN OUT [--force]`: the deck IN (text or HDF5, by its
   !> signature) written as OUT, an HDF5 deck when OUT ends in .h5, else a text deck. The
   !> output rule as for every deck: IN is never OUT, an existing OUT replaced only with
   !> --force and only when it is a deck.
   subroutine convert_deck_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(parsed_options) :: parsed
      type(status_type) :: status
      type(contact_problem) :: deck
      type(string_type), allocatable :: outputs(:), inputs(:)
      logical :: force
      code = 0
      call parse_options([flag_option("--force", "replace an existing deck (only a deck)")], args, parsed, status)
      if (status%code == 0 .and. size(parsed%positional) /= 2) call set_error(status, STATUS_USAGE, &
         "mkdeck convert takes two files, IN and OUT (found "//int_str(size(parsed%positional))//")")
      if (status%code /= 0) then
         call command_usage("mkdeck", status, code)
         return
      end if
      force = .false.
      call get_option(parsed, "--force", force)
      allocate(outputs(1), inputs(1))
      outputs(1)%s = parsed%positional(2)%s
      inputs(1)%s = parsed%positional(1)%s
      call guard_outputs(outputs, inputs, force, OUTPUT_DECK, status)
      if (status%code == 0) call read_deck(inputs(1)%s, deck, status)
      if (status%code == 0) call write_deck(outputs(1)%s, deck, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod mkdeck: "//status%message
         code = status%code
         return
      end if
      write(output_unit, '(a)') "wrote "//outputs(1)%s//" (NP = "//int_str(deck%np)//", MAXCONT = "// &
         int_str(deck%maxcont)//") from "//inputs(1)%s
   end subroutine convert_deck_command

   !> `femcod verify [-o FILE]`.
   subroutine verify_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(status_type) :: status
      type(parsed_options) :: parsed
      character(len=:), allocatable :: output
      type(string_type), allocatable :: none(:), report(:)
      logical :: force
      code = 0
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod verify [-o FILE] [--force]", &
            "Runs the legacy solver on the decks of input/ (run from the package root) and writes the", &
            "comparison with the thesis (Tables 4.1, 4.2, section 4.4.3, Fig. 5.2) to FILE", &
            "(default doc/verification.md). Takes about two minutes with the release build."
         return
      end if
      call parse_options([text_option("--output", "FILE", "the report (default doc/verification.md)", alias="-o"), &
         flag_option("--force", "replace an existing report (only one femcod generated)")], args, parsed, status)
      if (status%code == 0 .and. size(parsed%positional) > 0) &
         call set_error(status, STATUS_USAGE, "unknown argument "//parsed%positional(1)%s)
      if (status%code /= 0) then
         call command_usage("verify", status, code)
         return
      end if
      output = "doc/verification.md"
      force = .false.
      call get_option(parsed, "--output", output)
      call get_option(parsed, "--force", force)
      ! Checked before the two minutes of solves: femcod's output rule (io/femcod_output_guard).
      allocate(none(0), report(1))
      report(1)%s = output
      call guard_outputs(report, none, force, OUTPUT_RESULT, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod verify: "//status%message
         code = status%code
         return
      end if
      call write_verification_report(output, status, .true.)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod: "//status%message
         code = status%code
         return
      end if
      write(output_unit, '(a)') "wrote "//output
   end subroutine verify_command

   !> `names` without their blanks, comma-separated (the kinds, the verification decks).
   pure function comma_list(names) result(text)
      character(len=*), intent(in) :: names(:)
      character(len=:), allocatable :: text
      integer :: k
      text = trim(names(1))
      do k = 2, size(names)
         text = text//", "//trim(names(k))
      end do
   end function comma_list
end module femcod_cli
