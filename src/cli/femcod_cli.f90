!> The femcod command line. `femcod_command` reads the process arguments;
!> `run_femcod` takes them as a list, so tests drive the same code path. Returns the
!> exit code: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O.
module femcod_cli
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, STATUS_USAGE, STATUS_BAD_INPUT
   use femcod_deck, only: write_deck
   use femcod_problem, only: contact_problem
   use femcod_workspace, only: workspace_type, workspace_layout, workspace_table
   use femcod_generate, only: scene_spec, build_problem, verification_spec, VERIFICATION_DECKS, KINDS
   use femcod_heights, only: load_scene
   use femcod_run, only: run_command
   use femcod_studies, only: resolution_command, summits_command, multiscale_command
   use femcod_about, only: FEMCOD_VERSION
   use femcod_verification, only: write_verification_report
   use femcod_stability_report, only: write_stability_report
   use femcod_strings, only: string_type, int_str, parse_real, parse_integer, format_real
   implicit none
   private
   public :: femcod_command, run_femcod, command_arguments, FEMCOD_VERSION



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
      code = 0
      if (size(args) == 0) then
         call usage_error("no command given")
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
      case ("verify")
         call verify_command(args(2:), code)
      case ("stability")
         call stability_command(args(2:), code)
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
         "  workspace NP MAXCONT      print the Appendix B memory map (Tables B.1, B.2)", &
         "  verify [-o FILE]          recompute the thesis checks, write doc/verification.md", &
         "  stability [-o FILE]       run the hard cases, write doc/stability.md", &
         "  bench [--full]            speed against error, one table (use the release build)", &
         "  --help, --version", &
         "", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O"
   end subroutine print_help

   subroutine usage_error(message)
      character(len=*), intent(in) :: message
      write(error_unit, '(a)') "femcod: "//message//" (femcod --help)"
   end subroutine usage_error

   !> `femcod workspace NP MAXCONT`: one line per block, then the totals.
   subroutine workspace_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(workspace_type) :: ws
      type(status_type) :: status
      integer :: np, maxcont, k
      logical :: ok1, ok2
      character(len=120), allocatable :: lines(:)
      code = 0
      if (size(args) >= 1) then
         if (args(1)%s == "--help" .or. args(1)%s == "-h") then
            write(output_unit, '(a)') "usage: femcod workspace NP MAXCONT", &
               "Prints the memory map of the integer and real work arrays of Appendix B (Tables B.1, B.2):", &
               "block name, first address, size in words, contents; then IPEND, MPEND and the bytes they need.", &
               "MAXNODE = 4*MAXCONT+2; MPSTIF is femcod's skyline size (7*MAXCONT+2)*(MAXCONT+1)/2 (doc/workspace.md)."
            return
         end if
      end if
      if (size(args) /= 2) then
         call usage_error("workspace takes NP and MAXCONT")
         code = STATUS_USAGE
         return
      end if
      call parse_integer(args(1)%s, np, ok1)
      call parse_integer(args(2)%s, maxcont, ok2)
      if (.not. (ok1 .and. ok2)) then
         call usage_error("workspace: NP and MAXCONT must be integers")
         code = STATUS_USAGE
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

   subroutine mkdeck_help()
      write(output_unit, '(a)') &
         "usage: femcod mkdeck KIND -o FILE [options]", &
         "       femcod mkdeck --verification NAME|all [-o FILE | --dir DIR]", &
         "", &
         "Writes an input deck (doc/deck-format.md). The shape goes on one surface, the other is flat;", &
         "a rigid body gets E five orders of magnitude above the elastic one (thesis section 4.4),", &
         "and so do the contact/interface elements.", &
         "", &
         "kinds:", &
         "  circle-punch  flat circular punch: the round(area/d^2) pixels nearest the centre pixel (NP odd);", &
         "                --radius R [--area A (default pi R^2)] [--height H (default R)]", &
         "  square-punch  central NP/3 x NP/3 pixels (NP divisible by 3) [--height H (default NP d/3)]", &
         "  sphere        z = sqrt(R^2 - r^2) inside r < R, 0 outside; --radius R", &
         "  flat          constant height [--height H (default 0)]", &
         "  sinusoid      eq. 3.3: z = A cos(x/w) cos(y/w); [--amplitude A (1 nm)] [--scale w (10 nm)]", &
         "  wm            Weierstrass-Mandelbrot eq. 3.6; [--ds 2.4] [--g 1.36e-2 nm] [--gamma 1.5]", &
         "                [--lmax 1000 nm] [--lmin 1 nm] [--ridges 10] [--seed 1]", &
         "  self-affine   Gaussian random surface by FFT filtering, C(q) ~ q^-2(1+H) from 2pi/L to pi/d;", &
         "                [--hurst 0.8] [--rms 1 nm] [--seed 1]", &
         "  matrix        heights from --file FILE: an ASCII matrix (one row per line, '#' comments,", &
         "                Gwyddion export) or FILE.h5:/dataset (square, C order); [--remove-plane]", &
         "                subtracts the least-squares plane", &
         "", &
         "common options:", &
         "  -o FILE               output deck (written atomically)", &
         "  --np N                pixels per side (not for matrix)", &
         "  --pixel D             pixel size in nm", &
         "  --maxcont M           maximum contacts (default: the punch pixels for punches, NP^2 for flat,", &
         "                        else 5 % of NP^2)", &
         "  --young E --poisson NU  the elastic body (default 200 GPa, 0.25)", &
         "  --shape-on upper|lower  surface that carries the shape (default upper)", &
         "  --rigid upper|lower|none  rigid body (default upper)", &
         "  --rigid-factor R      modulus of the rigid body and of the contact/interface elements over", &
         "                        the elastic one (default 1e10: penalty error ~4e-11, doc/stability.md;", &
         "                        the thesis and input/ use 1e5; for --solver legacy 3e7 is best)", &
         "  --label TEXT          first line of the deck", &
         "", &
         "verification decks (input/): circle_punch_d1 d3 d9 (Table 4.1), square_punch_n1 n3 n9 n27", &
         "(Table 4.2), sphere_d4 d2 d1 d05 (Figs. 4.14-4.16), rough_selfaffine_32."
   end subroutine mkdeck_help

   !> `femcod mkdeck`.
   subroutine mkdeck_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: output, verification, dir, key
      integer :: i, k
      logical :: ok
      code = 0
      output = ""
      verification = ""
      dir = ""
      spec%kind = ""
      spec%label = ""
      spec%matrix_file = ""
      if (size(args) == 0) then
         call usage_error("mkdeck needs a KIND or --verification NAME")
         code = STATUS_USAGE
         return
      end if
      i = 1
      do while (i <= size(args))
         key = args(i)%s
         if (key == "--help" .or. key == "-h") then
            call mkdeck_help()
            return
         end if
         if (key == "--remove-plane") then
            spec%plane = .true.
            i = i + 1
            cycle
         end if
         if (key(1:min(1, len(key))) /= "-") then
            if (spec%kind /= "") then
               call usage_error("mkdeck: one KIND only, found '"//key//"'")
               code = STATUS_USAGE
               return
            end if
            spec%kind = key
            i = i + 1
            cycle
         end if
         if (i == size(args)) then
            call usage_error("mkdeck: option "//key//" needs a value")
            code = STATUS_USAGE
            return
         end if
         ok = .true.
         associate(v => args(i + 1)%s)
            select case (key)
            case ("-o", "--output")
               output = v
            case ("--dir")
               dir = v
            case ("--verification")
               verification = v
            case ("--label")
               spec%label = v
            case ("--file")
               spec%matrix_file = v
            case ("--shape-on")
               spec%shape_on = v
            case ("--rigid")
               spec%rigid = v
            case ("--np")
               call parse_integer(v, spec%np, ok)
            case ("--maxcont")
               call parse_integer(v, spec%maxcont, ok)
            case ("--seed")
               call parse_integer(v, spec%seed, ok)
            case ("--ridges")
               call parse_integer(v, spec%ridges, ok)
            case ("--pixel")
               call parse_real(v, spec%pixel, ok)
            case ("--young")
               call parse_real(v, spec%young, ok)
            case ("--poisson")
               call parse_real(v, spec%poisson, ok)
            case ("--rigid-factor")
               call parse_real(v, spec%rigid_factor, ok)
               if (ok) ok = spec%rigid_factor >= 1
            case ("--radius")
               call parse_real(v, spec%radius, ok)
            case ("--area")
               call parse_real(v, spec%area, ok)
            case ("--height")
               call parse_real(v, spec%height, ok)
            case ("--hurst")
               call parse_real(v, spec%hurst, ok)
            case ("--rms")
               call parse_real(v, spec%rms, ok)
            case ("--amplitude")
               call parse_real(v, spec%amplitude, ok)
            case ("--scale")
               call parse_real(v, spec%scale, ok)
            case ("--ds")
               call parse_real(v, spec%ds, ok)
            case ("--g")
               call parse_real(v, spec%g, ok)
            case ("--gamma")
               call parse_real(v, spec%gamma, ok)
            case ("--lmax")
               call parse_real(v, spec%lmax, ok)
            case ("--lmin")
               call parse_real(v, spec%lmin, ok)
            case default
               call usage_error("mkdeck: unknown option "//key)
               code = STATUS_USAGE
               return
            end select
            if (.not. ok) then
               call usage_error("mkdeck: option "//key//" expects a number (--rigid-factor: >= 1), found '"//v//"'")
               code = STATUS_USAGE
               return
            end if
         end associate
         i = i + 2
      end do

      if (verification /= "") then
         if (verification == "all") then
            if (dir == "") dir = "input"
            do k = 1, size(VERIFICATION_DECKS)
               call one_verification(trim(VERIFICATION_DECKS(k)), dir//"/"//trim(VERIFICATION_DECKS(k))//".deck")
               if (code /= 0) return
            end do
         else
            if (output == "") then
               if (dir == "") dir = "."
               output = dir//"/"//verification//".deck"
            end if
            call one_verification(verification, output)
         end if
         return
      end if

      if (spec%kind == "") then
         call usage_error("mkdeck: no KIND given (one of: "//kinds_list()//")")
         code = STATUS_USAGE
         return
      end if
      if (output == "") then
         call usage_error("mkdeck: -o FILE is required")
         code = STATUS_USAGE
         return
      end if
      if (spec%label == "") spec%label = "femcod mkdeck "//spec%kind
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

   !> `femcod verify [-o FILE]`.
   subroutine verify_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(status_type) :: status
      character(len=:), allocatable :: output
      code = 0
      output = "doc/verification.md"
      if (size(args) >= 1) then
         select case (args(1)%s)
         case ("-h", "--help")
            write(output_unit, '(a)') "usage: femcod verify [-o FILE]", &
               "Runs the legacy solver on the decks of input/ (run from the package root) and writes the", &
               "comparison with the thesis (Tables 4.1, 4.2, section 4.4.3, Fig. 5.2) to FILE", &
               "(default doc/verification.md). Takes about two minutes with the release build."
            return
         case ("-o")
            if (size(args) < 2) then
               call usage_error("verify: -o needs a file")
               code = STATUS_USAGE
               return
            end if
            output = args(2)%s
         case default
            call usage_error("verify: unknown argument "//args(1)%s)
            code = STATUS_USAGE
            return
         end select
      end if
      call write_verification_report(output, status, .true.)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod: "//status%message
         code = status%code
         return
      end if
      write(output_unit, '(a)') "wrote "//output
   end subroutine verify_command

   !> `femcod stability [-o FILE] [--events N]`.
   subroutine stability_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(status_type) :: status
      character(len=:), allocatable :: output
      integer :: i, events
      logical :: ok
      code = 0
      output = "doc/stability.md"
      events = 5000
      i = 1
      do while (i <= size(args))
         select case (args(i)%s)
         case ("-h", "--help")
            write(output_unit, '(a)') "usage: femcod stability [-o FILE] [--events N]", &
               "Runs the hard cases of doc/stability.md (stiff springs, ties and symmetry, degenerate scenes,", &
               "precision, a long run of N events, default 5000) and writes the table to FILE (default", &
               "doc/stability.md). About a minute with the release build."
            return
         case ("-o", "--events")
            if (i == size(args)) then
               call usage_error("stability: "//args(i)%s//" needs a value")
               code = STATUS_USAGE
               return
            end if
            if (args(i)%s == "-o") then
               output = args(i + 1)%s
            else
               call parse_integer(args(i + 1)%s, events, ok)
               if (.not. ok .or. events < 2) then
                  call usage_error("stability: --events expects an integer >= 2, found '"//args(i + 1)%s//"'")
                  code = STATUS_USAGE
                  return
               end if
            end if
            i = i + 2
         case default
            call usage_error("stability: unknown argument "//args(i)%s)
            code = STATUS_USAGE
            return
         end select
      end do
      call write_stability_report(output, events, status, .true.)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod: "//status%message
         code = status%code
         return
      end if
      write(output_unit, '(a)') "wrote "//output
   end subroutine stability_command

   function kinds_list() result(s)
      character(len=:), allocatable :: s
      integer :: k
      s = trim(KINDS(1))
      do k = 2, size(KINDS)
         s = s//", "//trim(KINDS(k))
      end do
   end function kinds_list
end module femcod_cli
