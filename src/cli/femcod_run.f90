!> `femcod run`: the contact history of decks (or of a pair of height files), each
!> solved by the solver the options name and written as one result set (PREFIX.h5,
!> .xdmf, the CSV files and the figures; doc/results.md), with a summary.
!>
!> The path of one run: the arguments are parsed against the option table (run_table)
!> into run_settings; each deck is read (or the scene built from its height files) into
!> a contact_problem; solvers/femcod_solver solves it, telling a run_observer of its
!> progress and handing it checkpoints; the maps of the reached loads are computed and
!> io/femcod_results writes the set.
module femcod_run
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_IO
   use femcod_strings, only: string_type, int_str, real_str, format_real
   use femcod_files, only: remove_file, path_exists, default_prefix, file_part
   use femcod_problem, only: contact_problem
   use femcod_deck, only: read_deck
   use femcod_generate, only: scene_spec
   use femcod_heights, only: load_scene
   use femcod_contact_result, only: contact_result, stop_reason_text
   use femcod_solver_options, only: contact_options
   use femcod_observer, only: solver_observer
   use femcod_state_visitor, only: visitable
   use femcod_incremental_state, only: incremental_state
   use femcod_solver, only: solve_contact, model_notes, report_lines, report_line
   use femcod_maps, only: load_maps, state_maps
   use femcod_checkpoint, only: write_checkpoint, read_checkpoint
   use femcod_wisdom, only: load_wisdom, save_wisdom
   use femcod_results, only: write_results, run_info, result_files
   use femcod_about, only: FEMCOD_VERSION
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, scene_options, flag_option, &
      real_option, integer_option, text_option, choice_option, real_list_option, get_option, option_given, &
      refuse_options
   implicit none
   private
   public :: run_command, run_table, run_settings, parse_run_arguments

   !> Everything `femcod run` was asked, after parsing.
   type :: run_settings
      !> The decks, in order ("" for the one scene of --lower/--upper).
      type(string_type), allocatable :: decks(:)
      !> Output prefix ("": each deck's name), FFTW wisdom file ("": none).
      character(len=:), allocatable :: prefix, wisdom
      logical :: quiet = .false., force = .false., restart = .false.
      !> The scene of --lower/--upper (kind "matrix").
      type(scene_spec) :: scene
      logical :: from_files = .false.
      !> The solver and its options.
      type(contact_options) :: solve
      !> The arguments as given, for the run record.
      character(len=:), allocatable :: command_line
   end type run_settings

   !> Progress lines on standard error and checkpoints to PREFIX.ckpt.h5, for one deck.
   type, extends(solver_observer) :: run_observer
      logical :: quiet = .false.
      !> Seconds of the last progress line.
      real(dp) :: last_report = 0
      !> What the run aims at, for the estimate of the time left: contacts, the largest
      !> requested load (nN, 0 if none), and how the cost grows with the contacts (n^3
      !> for the incremental solver, n^4 for the legacy one).
      integer :: target_contacts = 0
      real(dp) :: target_load = 0, growth = 3
      !> Where checkpoints go; whether a failure to write one was reported already.
      character(len=:), allocatable :: checkpoint_path
      logical :: warned = .false.
   contains
      procedure :: progress => report_progress
      procedure :: checkpoint => store_checkpoint
   end type run_observer

contains

   !> The options of `femcod run`. Modes: "heights" (--lower/--upper given), the solver's
   !> name, and "event" (the incremental and legacy solvers).
   function run_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [ &
         text_option("--output", "PREFIX", "output prefix (default: the deck's name without .deck, here)", alias="-o"), &
         choice_option("--solver", "incremental|legacy|cg", "the solver (default incremental; doc/solver.md)"), &
         real_list_option("--loads", "F1,...", "total loads in nN at which to report the state (PREFIX.loads.csv); "// &
            "the run stops once the largest is reached", lower=0.0_dp), &
         real_option("--hardness", "H", "GPa, for n_above_hardness (default 11, polysilicon)", lower=0.0_dp, closed="()"), &
         flag_option("--quiet", "no summary on standard output, no progress lines on standard error", alias="-q"), &
         flag_option("--force", "overwrite existing result files (otherwise a deck whose results exist fails with "// &
            "exit code 5 before it is solved)"), &
         integer_option("--max-contacts", "N", "stop after N contacts (default: the deck's MAXCONT)", lower=1, &
            mode="event"), &
         flag_option("--no-final-check", "skip the final check of every pixel for missed contacts", mode="event"), &
         choice_option("--event-search", "auto|bound|fft", "how the next contact is found: bound, a heap of lower "// &
            "bounds on the gaps and exact O(n) evaluations of the pixels that can close first; fft, gaps and rates "// &
            "of every pixel from two FFT convolutions; auto (default), the cheaper by a cost model; all three give "// &
            "the same events", mode="incremental"), &
         real_option("--checkpoint-interval", "S", "write PREFIX.ckpt.h5 (atomically) every S seconds of wall time "// &
            "(default 300; 0: after every step); removed at the end", lower=0.0_dp, mode="incremental"), &
         flag_option("--restart", "continue from PREFIX.ckpt.h5 if it exists (refused if it belongs to another deck "// &
            "or other options); the run ends exactly as an uninterrupted one", mode="incremental"), &
         real_option("--tol", "T", "stop when the gap violations over the height range are below T (default 1e-8)", &
            lower=0.0_dp, closed="()", mode="cg"), &
         integer_option("--max-iterations", "N", "iterations on the finest grid (default 2000)", lower=1, mode="cg"), &
         text_option("--fftw-wisdom", "FILE", "FFTW measures its plans once and keeps them in FILE and FILE.float32 "// &
            "(seconds of planning the first time, faster transforms)", mode="cg"), &
         text_option("--lower", "FILE", "lower surface heights: an ASCII matrix (a Gwyddion export with its "// &
            "units and width), FILE.h5:/dataset (square, C order: data[i, j] is row i, column j), or a NanoScope "// &
            "file FILE[:CHANNEL] (.di, .spm, .000; the height channel by default)"), &
         text_option("--upper", "FILE", "upper surface heights, the same formats (missing: flat)"), &
         scene_options("heights")]
   end function run_table

   subroutine run_help()
      write(output_unit, '(a)') &
         "usage: femcod run DECK [DECK ...] [-o PREFIX] [--solver incremental|legacy|cg] [--loads F1,F2,...] [options]", &
         "       femcod run --lower FILE [--upper FILE] [--pixel D] [scene options] [options]", &
         "", &
         "Contact history of each deck, step by step (thesis chapter 4, Appendix B). With several decks", &
         "(batch) each gets its own outputs named after it; a bad deck is reported and the others still", &
         "run; the exit code is that of the first failure, and a final summary lists the failures.", &
         "Solvers: incremental (default): event-exact, condensed to the contacts, bordered Cholesky factor,", &
         "exact candidate bound, full-field FFT check at the end; legacy: the Appendix B program (skyline,", &
         "COLHT, TRFACT, POSTP); cg: the state at each requested load only, by constrained conjugate", &
         "gradients (Polonsky-Keer) with FFT convolutions.", &
         ""
      call print_lines(option_help(run_table(), ""))
      write(output_unit, '(a)') "", "event solvers (incremental, legacy):"
      call print_lines(option_help(run_table(), "event"))
      write(output_unit, '(a)') "", "incremental solver:"
      call print_lines(option_help(run_table(), "incremental"))
      write(output_unit, '(a)') "", "cg solver (needs --loads):"
      call print_lines(option_help(run_table(), "cg"))
      write(output_unit, '(a)') "", "scene options, with --lower/--upper only (one scene; -o defaults to the first", &
         "file's name; the elastic body carries the heights, the other is rigid):"
      call print_lines(option_help(run_table(), "heights"))
      write(output_unit, '(a)') "", &
         "outputs: PREFIX.history.csv (step,contacts,load_nN,approach_nm,area_nm2,area_fraction,", &
         "         n_above_hardness),", &
         "         PREFIX.contacts.csv (i,j,step,force_nN,pressure_GPa) at the largest requested load", &
         "         or the last step, PREFIX.loads.csv (load_nN,approach_nm,contacts,area_nm2,area_fraction,", &
         "         max_pressure_GPa,n_above_hardness), PREFIX.h5 (everything, with the pressure and gap", &
         "         maps at each requested load; doc/results.md), PREFIX.xdmf (the maps for ParaView),", &
         "         PREFIX.load_approach.svg, PREFIX.area_load.svg, PREFIX.pressure_<k>.svg", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O"
   end subroutine run_help

   !> The arguments of `femcod run` as settings: parsed against run_table, the options
   !> that do not apply refused, the rules between options checked. No I/O.
   subroutine parse_run_arguments(args, settings, status)
      type(string_type), intent(in) :: args(:)
      type(run_settings), intent(out) :: settings
      type(status_type), intent(inout) :: status
      type(parsed_options) :: parsed
      character(len=:), allocatable :: lower, upper, modes
      integer :: d, k
      call parse_options(run_table(), args, parsed, status)
      if (status%code /= 0) return
      settings%command_line = ""
      do k = 1, size(args)
         settings%command_line = settings%command_line//args(k)%s
         if (k < size(args)) settings%command_line = settings%command_line//" "
      end do
      settings%prefix = ""
      settings%wisdom = ""
      call get_option(parsed, "--output", settings%prefix)
      call get_option(parsed, "--fftw-wisdom", settings%wisdom)
      call get_option(parsed, "--quiet", settings%quiet)
      call get_option(parsed, "--force", settings%force)
      call get_option(parsed, "--restart", settings%restart)
      associate(o => settings%solve)
         o%checkpoint_interval = 300
         allocate(o%loads(0))
         if (option_given(parsed, "--solver")) o%solver = option_value(parsed, "--solver")
         call get_option(parsed, "--loads", o%loads)
         call get_option(parsed, "--max-contacts", o%max_contacts)
         call get_option(parsed, "--hardness", o%hardness)
         if (option_given(parsed, "--no-final-check")) o%final_check = .false.
         if (option_given(parsed, "--event-search")) o%event_search = option_value(parsed, "--event-search")
         call get_option(parsed, "--checkpoint-interval", o%checkpoint_interval)
         call get_option(parsed, "--tol", o%cg%tol)
         call get_option(parsed, "--max-iterations", o%cg%max_iterations)
         o%cg%measure_plans = len(settings%wisdom) > 0
      end associate
      lower = ""
      upper = ""
      call get_option(parsed, "--lower", lower)
      call get_option(parsed, "--upper", upper)
      settings%from_files = len(lower) > 0 .or. len(upper) > 0
      ! The options that apply: height-file scene options with --lower/--upper only,
      ! each solver's own with that solver.
      modes = trim(settings%solve%solver)
      if (settings%solve%solver /= "cg") modes = modes//"|event"
      if (settings%from_files) modes = modes//"|heights"
      call refuse_options(parsed, modes, "heights=to height files (--lower/--upper), not to decks|"// &
         "event=to the event solvers (incremental, legacy), not to --solver cg|"// &
         "incremental=to the incremental solver only|cg=to --solver cg only", status)
      if (status%code /= 0) return
      settings%decks = parsed%positional
      do d = 2, size(settings%decks)
         do k = 1, d - 1
            if (settings%decks(k)%s == settings%decks(d)%s) then
               call set_error(status, STATUS_USAGE, "the deck '"//settings%decks(d)%s// &
                  "' is given twice (its results would overwrite each other)")
               return
            end if
         end do
      end do
      if (settings%from_files) then
         if (size(settings%decks) > 0) then
            call set_error(status, STATUS_USAGE, "give either DECK files or --lower/--upper height files, not both")
            return
         end if
         associate(spec => settings%scene)
            spec%kind = "matrix"
            spec%label = ""
            call get_option(parsed, "--label", spec%label)
            call get_option(parsed, "--pixel", spec%pixel)
            call get_option(parsed, "--young", spec%young)
            call get_option(parsed, "--poisson", spec%poisson)
            if (option_given(parsed, "--rigid")) spec%rigid = option_value(parsed, "--rigid")
            call get_option(parsed, "--rigid-factor", spec%rigid_factor)
            call get_option(parsed, "--maxcont", spec%maxcont)
            call get_option(parsed, "--remove-plane", spec%plane)
            if (option_given(parsed, "--height-unit")) spec%height_unit = option_value(parsed, "--height-unit")
            ! The surface given alone carries the shape, on the lower body; with both, the
            ! upper file is the shape and the lower the other surface.
            if (len(upper) == 0) then
               spec%matrix_file = lower
               spec%second_file = ""
               spec%shape_on = "lower"
            else
               spec%matrix_file = upper
               spec%second_file = lower
               spec%shape_on = "upper"
            end if
            if (spec%label == "") spec%label = "femcod run "//settings%command_line
            if (settings%prefix == "") settings%prefix = default_prefix(file_part(spec%matrix_file))
         end associate
         settings%decks = [string_type("")]
      end if
      if (size(settings%decks) == 0) then
         call set_error(status, STATUS_USAGE, "run needs a DECK")
      else if (settings%restart .and. settings%solve%solver /= "incremental") then
         call set_error(status, STATUS_USAGE, "--restart: checkpoints are written by the incremental solver only")
      else if (settings%solve%solver == "cg" .and. size(settings%solve%loads) == 0) then
         call set_error(status, STATUS_USAGE, "--solver cg solves at given loads: add --loads F1,F2,...")
      else if (size(settings%decks) > 1 .and. settings%prefix /= "") then
         call set_error(status, STATUS_USAGE, "-o PREFIX names the outputs of one deck; with several decks each "// &
            "deck's outputs are named after it, in the current directory")
      end if
   contains
      function option_value(p, name) result(v)
         type(parsed_options), intent(in) :: p
         character(len=*), intent(in) :: name
         character(len=:), allocatable :: v
         v = ""
         call get_option(p, name, v)
      end function option_value
   end subroutine parse_run_arguments

   !> `femcod run ARGS`: `code` is the exit code (of the first failing deck in a batch).
   subroutine run_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(run_settings) :: settings
      type(status_type) :: status
      type(string_type), allocatable :: failed(:)
      integer :: d, rc
      code = 0
      if (help_requested(args)) then
         call run_help()
         return
      end if
      call parse_run_arguments(args, settings, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod run: "//status%message//" (femcod run --help)"
         code = status%code
         return
      end if
      ! Batch: every deck runs; a failed deck is reported and the others go on.
      allocate(failed(0))
      do d = 1, size(settings%decks)
         associate(deck_path => settings%decks(d)%s)
            if (settings%prefix /= "") then
               call run_one(deck_path, settings%prefix, settings, rc)
            else
               call run_one(deck_path, default_prefix(deck_path), settings, rc)
            end if
            if (rc /= 0) then
               failed = [failed, string_type(deck_path)]
               if (code == 0) code = rc
            end if
         end associate
      end do
      if (size(settings%decks) > 1) then
         write(output_unit, '(a)') "femcod run: "//int_str(size(settings%decks))//" decks, "//int_str(size(failed))// &
            " failed"
         do d = 1, size(failed)
            write(output_unit, '(a)') "  failed: "//failed(d)%s
         end do
      end if
   end subroutine run_command

   !> One deck ("" for the height files): read, solve, write, report. `rc` is its exit code.
   subroutine run_one(deck_path, prefix, settings, rc)
      character(len=*), intent(in) :: deck_path, prefix
      type(run_settings), intent(in) :: settings
      integer, intent(out) :: rc
      type(contact_problem) :: problem
      type(contact_result) :: res
      type(status_type) :: st
      type(run_observer) :: observer
      type(incremental_state) :: resume
      type(state_maps), allocatable :: maps(:)
      type(run_info) :: info
      type(string_type), allocatable :: inputs(:), warnings(:)
      logical :: resuming, ok
      integer :: k
      rc = 0
      if (deck_path == "") then
         call load_scene(settings%scene, problem, st, inputs, warnings)
         do k = 1, size(warnings)
            write(error_unit, '(a)') "femcod: warning: "//warnings(k)%s
         end do
      else
         call read_deck(deck_path, problem, st)
         inputs = [string_type(deck_path//": femcod deck")]
      end if
      associate(options => settings%solve)
         ! With --restart, result files are leftovers of the interrupted run while its
         ! checkpoint exists, or while PREFIX.h5 (renamed last) does not; a complete set
         ! without a checkpoint means the run had finished: nothing to do.
         if (st%code == 0 .and. settings%restart .and. .not. settings%force) then
            if (path_exists(prefix//".h5") .and. .not. path_exists(prefix//".ckpt.h5")) then
               if (.not. settings%quiet) write(error_unit, '(a)') "femcod: "//prefix//".h5: the run of "// &
                  deck_label(deck_path)//" is complete; nothing to restart"
               return
            end if
         end if
         if (st%code == 0) call check_writable(prefix, st)
         if (st%code == 0 .and. .not. settings%force) then
            if (.not. (settings%restart .and. (path_exists(prefix//".ckpt.h5") .or. .not. path_exists(prefix//".h5")))) &
               call refuse_overwrite(prefix, size(options%loads), st)
         end if
         observer%quiet = settings%quiet
         observer%target_contacts = problem%maxcont
         if (options%max_contacts > 0) observer%target_contacts = min(observer%target_contacts, options%max_contacts)
         if (size(options%loads) > 0) observer%target_load = maxval(options%loads)
         observer%growth = merge(4.0_dp, 3.0_dp, options%solver == "legacy")
         observer%checkpoint_path = prefix//".ckpt.h5"
         resuming = .false.
         if (st%code == 0 .and. settings%restart) then
            if (path_exists(observer%checkpoint_path)) then
               call resume%init(problem, options)
               call read_checkpoint(observer%checkpoint_path, problem, options, resume, st)
               if (st%code == 0) call resume%rebuild(st)
               if (st%code /= 0 .and. index(st%message, observer%checkpoint_path) == 0) &
                  st%message = observer%checkpoint_path//": checkpoint refused: "//st%message
               resuming = st%code == 0
               if (resuming .and. .not. settings%quiet) write(error_unit, '(a)') "femcod: resuming "// &
                  deck_label(deck_path)//" from "//observer%checkpoint_path//" at step "//int_str(resume%step)//" ("// &
                  int_str(resume%n)//" contacts)"
            else if (.not. settings%quiet) then
               write(error_unit, '(a)') "femcod: no checkpoint "//observer%checkpoint_path//": starting "// &
                  deck_label(deck_path)//" from the beginning"
            end if
         end if
         if (st%code == 0 .and. options%solver == "cg" .and. len(settings%wisdom) > 0) &
            call load_wisdom(settings%wisdom, ok)
         if (st%code == 0) then
            if (resuming) then
               call solve_contact(problem, options, res, st, observer, resume)
            else
               call solve_contact(problem, options, res, st, observer)
            end if
         end if
         if (st%code == 0 .and. options%solver == "cg" .and. len(settings%wisdom) > 0) &
            call save_wisdom(settings%wisdom, st)
         if (st%code == 0) then
            info%version = FEMCOD_VERSION
            info%solver = trim(options%solver)
            info%options = settings%command_line
            info%scene = model_notes(problem, options)
            info%inputs = inputs
            call load_maps(problem, res%states, maps)
            call write_results(prefix, problem, res, maps, info, st)
         end if
         if (st%code /= 0) then
            write(error_unit, '(a)') "femcod: "//st%message
            rc = st%code
            return
         end if
         ! The results are safe: the checkpoint has served its purpose.
         if (options%solver == "incremental") call remove_file(prefix//".ckpt.h5")
         do k = 1, size(res%states)
            if (.not. res%states(k)%reached) write(error_unit, '(a)') "femcod: warning: load "// &
               format_real(res%states(k)%load)//" nN not reached ("//stop_reason_text(res%stop_reason)//")"
         end do
         if (.not. settings%quiet) call print_summary(deck_path, prefix, problem, options, res)
      end associate
   end subroutine run_one

   !> Before a long solve: can the results be written there at all?
   subroutine check_writable(prefix, st)
      character(len=*), intent(in) :: prefix
      type(status_type), intent(inout) :: st
      integer :: unit, ios
      open(newunit=unit, file=prefix//".history.csv.part", status="replace", action="write", iostat=ios)
      if (ios /= 0) then
         call set_error(st, STATUS_IO, prefix//".history.csv: cannot write (directory missing or not writable); "// &
            "nothing was run")
         return
      end if
      close(unit, status="delete")
   end subroutine check_writable

   !> A deck whose result files exist fails unless --force.
   subroutine refuse_overwrite(prefix, nloads, st)
      character(len=*), intent(in) :: prefix
      integer, intent(in) :: nloads
      type(status_type), intent(inout) :: st
      type(string_type), allocatable :: names(:)
      integer :: m
      names = result_files(prefix, nloads)
      do m = 1, size(names)
         if (path_exists(names(m)%s)) then
            call set_error(st, STATUS_IO, names(m)%s//": exists; not overwritten (use --force to replace the results)")
            return
         end if
      end do
   end subroutine refuse_overwrite

   !> The summary on standard output: the scene, the steps, the states at the requested
   !> loads, the wall time, then what the solver left out and checked.
   subroutine print_summary(deck_path, prefix, problem, options, res)
      character(len=*), intent(in) :: deck_path, prefix
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(in) :: res
      type(report_line), allocatable :: lines(:)
      integer :: k, last
      last = res%nsteps
      write(output_unit, '(a)') "femcod run "//deck_path//" (solver "//trim(options%solver)//")"
      write(output_unit, '(a)') "  scene     : "//problem%label
      write(output_unit, '(a)') "              NP = "//int_str(problem%np)//", d = "//format_real(problem%pixel)// &
         " nm, E = "//real_str(problem%young(1), 4)//" / "//real_str(problem%young(2), 4)//" / "// &
         real_str(problem%young(3), 4)//" GPa (lower / upper / contact)"
      write(output_unit, '(a)') "  steps     : "//int_str(last)//", stopped: "//stop_reason_text(res%stop_reason)
      if (last > 0) then
         write(output_unit, '(a)') "  last step : "//int_str(res%step_contacts(last))//" contacts up to load "// &
            real_str(res%step_load(last), 6)//" nN (where the next contact closes), approach "// &
            real_str(res%step_approach(last), 6)//" nm"
      end if
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         write(output_unit, '(a)') "  at load   : "//real_str(res%states(k)%load, 6)//" nN: approach "// &
            real_str(res%states(k)%approach, 6)//" nm, "//int_str(res%states(k)%contacts)//" contacts ("// &
            real_str(res%states(k)%contacts*problem%pixel**2, 4)//" nm^2), max pressure "// &
            real_str(res%states(k)%max_pressure, 4)//" GPa"
      end do
      write(output_unit, '(a)') "  wall time : "//real_str(res%wall_seconds, 3)//" s in total, "// &
         real_str(res%wall_seconds/max(last, 1), 3)//" s per step"
      lines = report_lines(problem, options, res)
      do k = 1, size(lines)
         write(output_unit, '(a)') "  "//lines(k)%label//repeat(" ", max(0, 10 - len(lines(k)%label)))//": "// &
            lines(k)%text
      end do
      write(output_unit, '(a)') "  written   : "//prefix//".h5, .xdmf, .history.csv, .contacts.csv, "// &
         ".load_approach.svg, .area_load.svg"//trim(merge(", .loads.csv, .pressure_<k>.svg", &
         repeat(" ", 31), size(res%states) > 0))
   end subroutine print_summary

   !> A progress line on standard error at most every 5 s, with an estimate of the time
   !> left from the cost model: a run to n contacts costs ~ n**growth; with a load
   !> target, the fraction of the load reached bounds the fraction of contacts.
   subroutine report_progress(self, step, contacts, load, elapsed)
      class(run_observer), intent(inout) :: self
      integer, intent(in) :: step, contacts
      real(dp), intent(in) :: load, elapsed
      real(dp) :: fraction, left
      character(len=:), allocatable :: estimate
      if (self%quiet .or. elapsed - self%last_report < 5) return
      self%last_report = elapsed
      fraction = real(contacts, dp)/max(self%target_contacts, 1)
      if (self%target_load > 0) fraction = max(fraction, min(load/self%target_load, 1.0_dp))
      estimate = ""
      if (fraction > 0 .and. fraction < 1) then
         left = elapsed*(fraction**(-self%growth) - 1)
         estimate = ", about "//real_str(left, 2)//" s left (cost ~ contacts^"//int_str(nint(self%growth))//")"
      end if
      write(error_unit, '(a)') "femcod: event "//int_str(step)//", "//int_str(contacts)//" contacts, load "// &
         real_str(load, 5)//" nN, "//real_str(elapsed, 3)//" s elapsed"//estimate
      flush(error_unit)
   end subroutine report_progress

   !> Store the solver's state in PREFIX.ckpt.h5; a failure to write is reported once and
   !> the run goes on.
   subroutine store_checkpoint(self, problem, options, state)
      class(run_observer), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      class(visitable), intent(inout) :: state
      type(status_type) :: st
      call write_checkpoint(self%checkpoint_path, problem, options, state, st)
      if (st%code /= 0 .and. .not. self%warned) then
         write(error_unit, '(a)') "femcod: warning: checkpoint not written: "//st%message
         flush(error_unit)
         self%warned = .true.
      end if
   end subroutine store_checkpoint

   !> How a deck is named in messages.
   function deck_label(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      name = path
      if (path == "") name = "the height files"
   end function deck_label
end module femcod_run
