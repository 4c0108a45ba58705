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
   use femcod_kinds, only: dp, i8
   use femcod_memory, only: available_memory, resident_bytes
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_IO, STATUS_INTERRUPTED
   use femcod_strings, only: sig_str, string_type, int_str, format_real, append_string, count_text
   use femcod_files, only: remove_file, path_exists, path_is_directory, default_prefix, file_part, canonical_path, &
      acquire_lock, release_lock, make_directories
   use femcod_process, only: catch_stop_signals, stop_signal, signal_name, host_name, local_time_iso
   use femcod_sha256, only: sha256_hex, file_digest, file_sha256_start, file_sha256_finish
   use femcod_clock, only: wall_clock
   use femcod_problem, only: contact_problem
   use femcod_deck, only: read_deck
   use femcod_generate, only: scene_spec
   use femcod_heights, only: load_scene, height_file_path, is_height_file, looks_like_height_matrix
   use femcod_contact_result, only: contact_result, load_state, stop_reason_text, STOP_INTERRUPTED, cg_state_diagnostics, cg_work
   use femcod_solver_options, only: contact_options, requested_states, validate_options, history_options, &
      SOLVER_LEGACY, SOLVER_CG, BOUNDARY_PERIODIC, LAW_HARD_WALL, solver_name, boundary_name, law_name, &
      run_shear_model, OPTION_NAMES, option_field
   use femcod_shear_model, only: shear_model, friction_coefficient
   use femcod_cerruti, only: second_dundurs_constant
   use femcod_observer, only: solver_observer
   use femcod_state_visitor, only: visitable
   use femcod_incremental_state, only: incremental_state
   use femcod_solver, only: solve_contact, model_notes, report_lines, report_line, run_warnings
   use femcod_maps, only: load_maps, state_maps
   use femcod_patches, only: contact_patches, perimeter_area_fit
   use femcod_checkpoint, only: write_checkpoint, read_checkpoint
   use femcod_wisdom, only: load_wisdom, save_wisdom
   use femcod_output_guard, only: guard_outputs, OUTPUT_WISDOM, OUTPUT_RESULT
   use femcod_results, only: write_results, run_info, result_files, stored_fingerprint, pressure_figure_wanted, &
      FIGURES_AUTO_LIMIT, HISTORY_HEADER, LOADS_HEADER, CONTACTS_HEADER, FRICTION_COLUMNS, PATCH_COLUMNS
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
      !> The decks, in order ("" for the one scene of --lower/--upper), and the output
      !> prefix of each.
      type(string_type), allocatable :: decks(:), prefixes(:)
      !> Output prefix ("": each deck's name), directory of the outputs ("": here), FFTW
      !> wisdom file ("": none).
      character(len=:), allocatable :: prefix, outdir, wisdom
      logical :: quiet = .false., force = .false., restart = .false.
      !> Which states get a pressure figure (--figures all|last|none|auto).
      character(len=:), allocatable :: figures
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
      !> What a progress step is: "event" (the event solvers), "load" or "approach" (cg's
      !> states, of `states` asked).
      character(len=:), allocatable :: step_word
      integer :: states = 0
      !> Where checkpoints go; whether a failure to write one was reported already, and
      !> whether one was stored.
      character(len=:), allocatable :: checkpoint_path
      logical :: warned = .false., stored = .false.
   contains
      procedure :: configure => configure_observer
      procedure :: progress => report_progress
      procedure :: checkpoint => store_checkpoint
      procedure :: stop_requested => signal_arrived
   end type run_observer

   !> Appended to the fingerprint of a partial run (a stop signal between two requested
   !> states of cg or legacy): --restart runs it again rather than calling it complete.
   character(len=*), parameter :: PARTIAL_MARK = " (partial)"

contains

   !> The options of `femcod run`. Modes: "heights" (--lower/--upper given), the solver's
   !> name, and "event" (the incremental and legacy solvers).
   function run_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [ &
         text_option("--output", "PREFIX", "output prefix (default: the deck's name without .deck, here; its "// &
            "directory is made if missing)", alias="-o"), &
         text_option("--outdir", "DIR", "write each deck's outputs into DIR (made if missing), named after the deck"), &
         choice_option("--solver", "incremental|legacy|cg", "the solver (default incremental; doc/solver.md)"), &
         real_list_option("--loads", "F1,...", "total loads in nN at which to report the state (PREFIX.loads.csv); "// &
            "the run stops once the largest is reached", lower=0.0_dp), &
         real_option("--hardness", "H", "GPa, for n_above_hardness (default 11, polysilicon), and the cap of "// &
            "--plastic", lower=0.0_dp, closed="()"), &
         real_list_option("--approach", "D1,...", "displacement control instead of --loads: approaches in nm "// &
            "(from first touch; any order) at which to report the state, the load being the answer "// &
            "(PREFIX.loads.csv, one row per approach in the order given)"), &
         choice_option("--boundary", "free|periodic", "free (default): the grid alone on a half-space, as in the "// &
            "thesis; periodic: the grid is one cell of a surface repeating with period NP d in both directions "// &
            "(incremental and cg solvers; zero-mean displacements, the approach is the fall of the mean gap)"), &
         flag_option("--plastic", "elastic-perfectly-plastic interface: no pixel's pressure exceeds the hardness; "// &
            "a capped pixel carries H d^2 and interpenetrates (its plastic displacement, in PREFIX.h5)", &
            mode="cg|incremental"), &
         flag_option("--quiet", "no summary on standard output, no progress lines on standard error", alias="-q"), &
         choice_option("--figures", "auto|all|last|none", "which states get a pressure figure PREFIX.pressure_<k>.svg "// &
            "(default auto: every state up to "// &
            int_str(FIGURES_AUTO_LIMIT)//" asked, beyond that the last reached one only; the maps are in "// &
            "PREFIX.h5 either way)"), &
         flag_option("--force", "replace existing results as a whole set, and a checkpoint of an interrupted run "// &
            "(otherwise both are kept and the deck fails with exit code 5 before it is solved); an input file is "// &
            "never an output"), &
         integer_option("--max-contacts", "N", "stop after N contacts, in place of the deck's MAXCONT", lower=1, &
            mode="event"), &
         flag_option("--no-final-check", "skip the final check of every pixel for missed contacts", mode="event"), &
         choice_option("--event-search", "auto|bound|fft", "how the next contact is found: bound, a heap of lower "// &
            "bounds on the gaps and exact O(n) evaluations of the pixels that can close first; fft, gaps and rates "// &
            "of every pixel from two FFT convolutions; auto (default), the cheaper by a cost model; all three give "// &
            "the same events", mode="incremental"), &
         real_option("--checkpoint-interval", "S", "write PREFIX.ckpt.h5 (atomically) every S seconds of wall time "// &
            "(default 300; 0: after every step); removed at the end", lower=0.0_dp, mode="incremental"), &
         flag_option("--restart", "continue from PREFIX.ckpt.h5 if it exists (refused if it belongs to another deck "// &
            "or other options); the run ends exactly as an uninterrupted one. Complete results of the same inputs "// &
            "and options: nothing to do; of others: refused. With a solver that keeps no checkpoint (cg, legacy) "// &
            "the run starts afresh, so a resubmitted job array runs with every solver; a partial set they left on a "// &
            "stop signal (the states finished before it, summary 'stopped': 'interrupted') is run again"), &
         real_option("--tol", "T", "stop when the gap violations over the height range are below T (default 1e-8; "// &
            "with --adhesion the force-balance violations times a pixel's compliance)", &
            lower=0.0_dp, closed="()", mode="cg"), &
         integer_option("--max-iterations", "N", "iterations on the finest grid (default 2000)", lower=1, mode="cg"), &
         real_option("--kernel-radius", "R", "truncate the Love kernel beyond R pixels (an approximation: the "// &
            "thesis' open question 5.2.2 iii, measured by femcod bench frontier; default: the whole kernel)", &
            lower=0.0_dp, closed="()", mode="cg"), &
         choice_option("--adhesion", "dugdale|exponential", "adhesive interface, with --approach, --work and "// &
            "--range: Dugdale, a tension W/R wherever 0 < gap < R; exponential, a tension (W/R) exp(-gap/R); the "// &
            "approaches are followed in the order given, each from the last (loading and unloading branches, "// &
            "jumps into contact and pull-off)", mode="cg"), &
         real_option("--work", "W", "work of adhesion in J/m^2 (= nN/nm), with --adhesion", lower=0.0_dp, mode="cg"), &
         real_option("--shear-strength", "TAU0", "friction from the pressures (thesis 5.2.3): each contact pixel "// &
            "carries the shear strength TAU0 + ALPHA p (GPa; with --plastic capped at the shear yield stress "// &
            "H/(3 sqrt 3)); adds friction_nN and friction_coefficient to the history and loads (default 0)", &
            lower=0.0_dp), &
         real_option("--shear-slope", "ALPHA", "the shear strength's pressure coefficient ALPHA (1, default 0)", &
            lower=0.0_dp), &
         real_option("--tangential", "Q", "after the normal problem, a tangential force Q (nN, along x) at each "// &
            "state with Coulomb friction (--friction): partial slip by the Cerruti kernel, stick and slip maps, the "// &
            "tangential shift; Q >= mu P slides", lower=0.0_dp), &
         real_option("--slip", "S", "as --tangential, a rigid tangential shift S (nm, along x) instead of a force", &
            lower=0.0_dp), &
         real_option("--friction", "MU", "the Coulomb coefficient of --tangential or --slip", lower=0.0_dp, &
            closed="()"), &
         real_option("--range", "R", "range of the adhesion law in nm, with --adhesion", lower=0.0_dp, closed="()", &
            mode="cg"), &
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
      write(output_unit, '(a)') "", "incremental and cg solvers (not the legacy one):"
      call print_lines(option_help(run_table(), "cg|incremental"))
      write(output_unit, '(a)') "", "cg solver (needs --loads or --approach; MAXCONT and --max-contacts do not apply):"
      call print_lines(option_help(run_table(), "cg"))
      write(output_unit, '(a)') "", "scene options, with --lower/--upper only (one scene; -o defaults to the first", &
         "file's name; the elastic body carries the heights, the other is rigid):"
      call print_lines(option_help(run_table(), "heights"))
      write(output_unit, '(a)') "", &
         "outputs: PREFIX.history.csv, one row per step:", &
         "           "//HISTORY_HEADER, &
         "         PREFIX.contacts.csv, at the largest requested load or the last step:", &
         "           "//CONTACTS_HEADER, &
         "         PREFIX.loads.csv, one row per requested load or approach:", &
         "           "//LOADS_HEADER//PATCH_COLUMNS, &
         "         (patches_4, patches_8: the contact patches, 4- and 8-connected; --shear-strength", &
         "         and --shear-slope add "//FRICTION_COLUMNS(2:)//", a tangential step its own, before them),", &
         "         PREFIX.h5 (everything, with the pressure and gap", &
         "         maps at each requested load; doc/results.md), PREFIX.xdmf (the maps on a mesh for", &
         "         ParaView and meshio), PREFIX.summary.json (the summary as numbers with units),", &
         "         PREFIX.load_approach.svg, PREFIX.area_load.svg, PREFIX.pressure_<k>.svg.", &
         "         PREFIX.lock exists while a run writes the prefix; another run is refused.", &
         "signals: SIGTERM, SIGINT and SIGUSR1 stop the run at the next step; the incremental solver", &
         "         writes its checkpoint (continue with --restart), no result file is left half written.", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure or memory, 5 I/O (results or a", &
         "         checkpoint exist, a lock is held, disk full), 128 + N stopped by signal N (143 SIGTERM,", &
         "         130 SIGINT, 138 SIGUSR1)"
   end subroutine run_help

   !> The solver's options from the parsed arguments of `femcod run` (no rules checked:
   !> validate_options and parse_run_arguments do that).
   subroutine solve_options_from(parsed, o)
      type(parsed_options), intent(in) :: parsed
      type(contact_options), intent(out) :: o
      character(len=:), allocatable :: text
      integer :: k
      o%checkpoint_interval = 300
      allocate(o%loads(0), o%approaches(0))
      do k = 1, size(OPTION_NAMES)
         if (len_trim(OPTION_NAMES(k)) == 0) cycle
         if (.not. option_given(parsed, trim(OPTION_NAMES(k)))) cycle
         text = option_value(parsed, trim(OPTION_NAMES(k)))
         call option_field(o, k, text, .true.)
      end do
   end subroutine solve_options_from

   !> The text of option `name` ("" when not given).
   function option_value(p, name) result(v)
      type(parsed_options), intent(in) :: p
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: v
      v = ""
      call get_option(p, name, v)
   end function option_value

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
      settings%outdir = ""
      settings%wisdom = ""
      call get_option(parsed, "--output", settings%prefix)
      call get_option(parsed, "--outdir", settings%outdir)
      call get_option(parsed, "--fftw-wisdom", settings%wisdom)
      call get_option(parsed, "--quiet", settings%quiet)
      settings%figures = "auto"
      call get_option(parsed, "--figures", settings%figures)
      call get_option(parsed, "--force", settings%force)
      call get_option(parsed, "--restart", settings%restart)
      call solve_options_from(parsed, settings%solve)
      settings%solve%cg%measure_plans = len(settings%wisdom) > 0
      lower = ""
      upper = ""
      call get_option(parsed, "--lower", lower)
      call get_option(parsed, "--upper", upper)
      settings%from_files = len(lower) > 0 .or. len(upper) > 0
      ! The options that apply: height-file scene options with --lower/--upper only,
      ! each solver's own with that solver.
      modes = solver_name(settings%solve%solver)
      if (settings%solve%solver /= SOLVER_CG) modes = modes//"|event"
      if (settings%from_files) modes = modes//"|heights"
      call refuse_options(parsed, modes, "heights=to height files (--lower/--upper), not to decks|"// &
         "event=to the event solvers (incremental, legacy), not to --solver cg|"// &
         "incremental=to the incremental solver only|cg=to --solver cg only", status)
      if (status%code /= 0) return
      settings%decks = parsed%positional
      ! A scan given where a deck belongs (femcod run scan.spm): say how to run it.
      do d = 1, size(settings%decks)
         if (is_height_file(settings%decks(d)%s)) then
            call set_error(status, STATUS_USAGE, settings%decks(d)%s//" is a height file (an instrument or HDF5 "// &
               "scan), not a deck: run it with --lower "//settings%decks(d)%s//" (and --pixel D if it does not "// &
               "give its pixel size)")
            return
         end if
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
            if (spec%label == "") spec%label = "femcod run"//scene_arguments(args)
            if (settings%prefix == "" .and. settings%outdir /= "") then
               settings%prefix = settings%outdir//"/"//default_prefix(file_part(spec%matrix_file))
            else if (settings%prefix == "") then
               settings%prefix = default_prefix(file_part(spec%matrix_file))
            end if
         end associate
         settings%decks = [string_type("")]
      end if
      ! Which options go together: one rule set for run, femcod-mpi and the benchmarks.
      call validate_options(settings%solve, status)
      if (status%code /= 0) return
      if (settings%solve%solver == SOLVER_CG .and. option_given(parsed, "--maxcont")) then
         call set_error(status, STATUS_USAGE, "--maxcont with --solver cg: cg solves at the loads or approaches "// &
            "asked and has no contact limit (MAXCONT bounds the event solvers)")
         return
      end if
      if (size(settings%decks) == 0) then
         call set_error(status, STATUS_USAGE, "run needs a DECK")
      else if (option_given(parsed, "--tangential") .and. option_given(parsed, "--slip")) then
         call set_error(status, STATUS_USAGE, "give --tangential Q (a force) or --slip S (a shift), not both")
      else if (option_given(parsed, "--friction") .and. .not. settings%solve%tangential) then
         call set_error(status, STATUS_USAGE, "--friction MU is the Coulomb coefficient of a tangential step: add "// &
            "--tangential Q or --slip S")
      else if (settings%solve%adhesion /= LAW_HARD_WALL .and. .not. (option_given(parsed, "--work") .and. &
         option_given(parsed, "--range"))) then
         call set_error(status, STATUS_USAGE, "--adhesion needs --work W (J/m^2) and --range R (nm)")
      else if (settings%solve%adhesion == LAW_HARD_WALL .and. (option_given(parsed, "--work") .or. &
         option_given(parsed, "--range"))) then
         call set_error(status, STATUS_USAGE, "--work and --range describe an adhesion law: add --adhesion "// &
            "dugdale|exponential")
      else if (size(settings%decks) > 1 .and. settings%prefix /= "" .and. .not. settings%from_files) then
         call set_error(status, STATUS_USAGE, "-o PREFIX names the outputs of one deck; with several decks each "// &
            "deck's outputs are named after it (--outdir DIR puts them in DIR)")
      else if (option_given(parsed, "--output") .and. settings%outdir /= "") then
         call set_error(status, STATUS_USAGE, "give -o PREFIX or --outdir DIR, not both")
      else if (settings%prefix /= "") then
         if (settings%prefix(len(settings%prefix):) == "/" .or. path_is_directory(settings%prefix)) &
            call set_error(status, STATUS_USAGE, "-o takes a prefix such as "//without_slash(settings%prefix)// &
            "/name, not a directory (or use --outdir DIR)")
      end if
      if (status%code /= 0) return
      call assign_prefixes(settings, status)
   end subroutine parse_run_arguments

   !> `femcod run ARGS`: `code` is the exit code (of the first failing deck in a batch;
   !> 128 + the signal's number after SIGTERM, SIGINT or SIGUSR1).
   subroutine run_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(run_settings) :: settings
      type(status_type) :: status
      type(string_type), allocatable :: failed(:)
      integer :: d, rc, k
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
      if (len(settings%wisdom) > 0) call check_wisdom_file(settings, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod run: "//status%message
         code = status%code
         return
      end if
      if (settings%outdir /= "") then
         call make_directories(settings%outdir, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod: "//status%message
            code = status%code
            return
         end if
      end if
      ! -o out/circle in a fresh directory: out/ is made, as --outdir makes its DIR.
      do d = 1, size(settings%prefixes)
         k = index(settings%prefixes(d)%s, "/", back=.true.)
         if (k <= 1) cycle
         if (path_is_directory(settings%prefixes(d)%s(1:k - 1))) cycle
         call make_directories(settings%prefixes(d)%s(1:k - 1), status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod: "//status%message
            code = status%code
            return
         end if
      end do
      ! A batch system's stop signals end the run between two steps, with a checkpoint.
      call catch_stop_signals()
      ! Batch: every deck runs; a failed deck is reported and the others go on.
      allocate(failed(0))
      do d = 1, size(settings%decks)
         call run_one(settings%decks(d)%s, settings%prefixes(d)%s, settings, rc)
         if (rc /= 0) then
            call append_string(failed, settings%decks(d)%s)
            if (code == 0) code = rc
         end if
         ! A signal stops the batch. One that arrives after the last deck's results are
         ! written leaves nothing undone: the exit code stays that of the work.
         if (stop_signal() /= 0 .and. d < size(settings%decks)) then
            code = 128 + stop_signal()
            write(error_unit, '(a)') "femcod: "//signal_name(stop_signal())// &
               ": the batch stops; "//int_str(size(settings%decks) - d)// &
               trim(merge(" deck not run ", " decks not run", size(settings%decks) - d == 1))
            exit
         end if
      end do
      if (size(settings%decks) > 1) then
         write(output_unit, '(a)') "femcod run: "//int_str(size(settings%decks))//" decks, "//int_str(size(failed))// &
            " failed"
         do d = 1, size(failed)
            write(output_unit, '(a)') "  failed: "//failed(d)%s
         end do
      end if
   end subroutine run_command

   !> One deck ("" for the height files): read, lock its prefix, solve, write, report.
   !> `rc` is its exit code.
   subroutine run_one(deck_path, prefix, settings, rc)
      character(len=*), intent(in) :: deck_path, prefix
      type(run_settings), intent(in) :: settings
      integer, intent(out) :: rc
      type(contact_problem) :: problem
      type(status_type) :: st
      type(string_type), allocatable :: inputs(:), warnings(:), files(:)
      type(file_digest), allocatable :: pending(:)
      character(len=:), allocatable :: notice, hex
      real(dp) :: t0, read_seconds
      integer :: k
      rc = 0
      call wall_clock(t0)
      if (deck_path == "") then
         call load_scene(settings%scene, problem, st, inputs, warnings)
         do k = 1, size(warnings)
            write(error_unit, '(a)') "femcod: warning: "//warnings(k)%s
         end do
         allocate(files(0))
         if (st%code == 0) then
            call append_string(files, height_file_path(settings%scene%matrix_file))
            if (settings%scene%second_file /= "") call append_string(files, height_file_path(settings%scene%second_file))
         end if
         allocate(pending(size(files)))
         do k = 1, size(files)
            call file_sha256_start(files(k)%s, pending(k))
         end do
      else
         ! The deck's digest is taken while it is read.
         allocate(pending(1))
         call file_sha256_start(deck_path, pending(1))
         call read_deck(deck_path, problem, st)
         if (st%code /= 0 .and. looks_like_height_matrix(deck_path)) then
            st%code = STATUS_USAGE
            st%message = deck_path//" reads as a matrix of heights, not as a deck: run it with --lower "// &
               deck_path//" --pixel D ("//st%message//")"
         end if
         inputs = [string_type(deck_path//": femcod deck")]
         files = [string_type(deck_path)]
      end if
      call wall_clock(read_seconds)
      read_seconds = read_seconds - t0
      ! No output may ever replace an input.
      if (st%code == 0) call refuse_input_as_output(prefix, requested_states(settings%solve), files, st)
      if (st%code == 0) then
         call acquire_lock(prefix//".lock", st, notice)
         if (notice /= "" .and. .not. settings%quiet) write(error_unit, '(a)') "femcod: "//notice
         if (st%code == 0) then
            call run_locked(deck_path, prefix, settings, problem, inputs, files, pending, read_seconds, st)
            call release_lock(prefix//".lock")
         end if
      end if
      ! Digests not collected (a run refused before it started) are waited for here.
      do k = 1, size(pending)
         hex = file_sha256_finish(pending(k))
      end do
      if (st%code /= 0) then
         if (st%code == STATUS_INTERRUPTED) then
            write(error_unit, '(a)') "femcod: "//signal_name(stop_signal())//": "//st%message
            rc = 128 + stop_signal()
         else
            write(error_unit, '(a)') "femcod: "//st%message
            rc = st%code
         end if
      end if
   end subroutine run_one

   !> Each deck's output prefix (-o, --outdir DIR/NAME, or NAME beside the run); two
   !> decks may not be one file nor write the same files.
   subroutine assign_prefixes(settings, status)
      type(run_settings), intent(inout) :: settings
      type(status_type), intent(inout) :: status
      integer :: d, k
      allocate(settings%prefixes(size(settings%decks)))
      do d = 1, size(settings%decks)
         if (settings%prefix /= "") then
            settings%prefixes(d)%s = settings%prefix
         else if (settings%outdir /= "") then
            settings%prefixes(d)%s = settings%outdir//"/"//default_prefix(settings%decks(d)%s)
         else
            settings%prefixes(d)%s = default_prefix(settings%decks(d)%s)
         end if
         do k = 1, d - 1
            if (canonical_path(settings%decks(k)%s) == canonical_path(settings%decks(d)%s)) then
               call set_error(status, STATUS_USAGE, "the deck '"//settings%decks(d)%s//"' is given twice (as '"// &
                  settings%decks(k)%s//"'; its results would overwrite each other)")
               return
            end if
            if (canonical_path(settings%prefixes(k)%s) == canonical_path(settings%prefixes(d)%s)) then
               call set_error(status, STATUS_USAGE, settings%decks(k)%s//" and "//settings%decks(d)%s// &
                  " would both write "//settings%prefixes(d)%s//".*: run them apart, each with its -o")
               return
            end if
         end do
      end do
   end subroutine assign_prefixes

   !> The arguments that define a height-file scene (the files and the scene options),
   !> for its label: not -o, --restart, --force and the like, so that a restart with
   !> other operational options finds its checkpoint.
   function scene_arguments(list) result(text)
      type(string_type), intent(in) :: list(:)
      character(len=:), allocatable :: text
      type(option_spec), allocatable :: scene(:)
      integer :: i, j
      scene = [scene_options("heights"), text_option("--lower", "FILE", ""), text_option("--upper", "FILE", "")]
      text = ""
      i = 1
      do while (i <= size(list))
         do j = 1, size(scene)
            if (list(i)%s == scene(j)%name) then
               text = text//" "//list(i)%s
               if (scene(j)%value_name /= "" .and. i < size(list)) then
                  i = i + 1
                  text = text//" "//list(i)%s
               end if
               exit
            end if
         end do
         i = i + 1
      end do
   end function scene_arguments

   !> --fftw-wisdom FILE, before any deck is read: FILE and FILE.float32 are neither an
   !> input nor a result file of this run, and each that exists is FFTW wisdom (it is
   !> then read and brought up to date without --force: that is what the option is for);
   !> a file that is not wisdom is refused and left as it is.
   subroutine check_wisdom_file(settings, st)
      type(run_settings), intent(in) :: settings
      type(status_type), intent(inout) :: st
      type(string_type), allocatable :: inputs(:), outputs(:)
      type(string_type) :: wisdom(2)
      integer :: d, m, w
      allocate(inputs(0), outputs(0))
      do d = 1, size(settings%decks)
         if (settings%decks(d)%s /= "") then
            call append_string(inputs, settings%decks(d)%s)
         else
            call append_string(inputs, height_file_path(settings%scene%matrix_file))
            if (settings%scene%second_file /= "") &
               call append_string(inputs, height_file_path(settings%scene%second_file))
         end if
         outputs = [outputs, result_files(settings%prefixes(d)%s, requested_states(settings%solve)), &
            string_type(settings%prefixes(d)%s//".ckpt.h5"), string_type(settings%prefixes(d)%s//".lock")]
      end do
      wisdom(1)%s = settings%wisdom
      wisdom(2)%s = settings%wisdom//".float32"
      do w = 1, size(wisdom)
         do m = 1, size(outputs)
            if (canonical_path(wisdom(w)%s) == canonical_path(outputs(m)%s)) then
               call set_error(st, STATUS_USAGE, "--fftw-wisdom: "//wisdom(w)%s//" is also a result file of this "// &
                  "run; give the wisdom a name of its own")
               return
            end if
         end do
      end do
      call guard_outputs(wisdom, inputs, .true., OUTPUT_WISDOM, st)
      if (st%code /= 0) st%message = "--fftw-wisdom: "//st%message
   end subroutine check_wisdom_file

   !> What exists under `prefix` before a run: with --restart, a complete set of the same
   !> inputs and options (`complete`: nothing to do) or of others (refused); a checkpoint
   !> without --restart or --force (refused); existing results without --force (refused);
   !> and with --force (or as a restart's leftovers) only files femcod wrote are replaced.
   subroutine check_existing(deck_path, prefix, settings, fingerprint, have_checkpoint, complete, st)
      character(len=*), intent(in) :: deck_path, prefix, fingerprint
      type(run_settings), intent(in) :: settings
      logical, intent(out) :: have_checkpoint, complete
      type(status_type), intent(inout) :: st
      character(len=:), allocatable :: stored
      type(string_type), allocatable :: names(:), none(:), checkpoint(:)
      logical :: partial
      complete = .false.
      have_checkpoint = path_exists(prefix//".ckpt.h5")
      ! With --restart, result files are leftovers of the interrupted run while its
      ! checkpoint exists, or while PREFIX.h5 (renamed last) does not. A complete set
      ! without a checkpoint means the run had finished: nothing to do, if it is the
      ! run of these inputs and options.
      partial = .false.
      if (settings%restart .and. .not. settings%force .and. .not. have_checkpoint .and. &
         path_exists(prefix//".h5")) then
         stored = stored_fingerprint(prefix//".h5")
         ! The partial set of an interrupted cg or legacy run: --restart runs it again.
         partial = stored == fingerprint//PARTIAL_MARK
         if (stored == fingerprint) then
            if (.not. settings%quiet) write(error_unit, '(a)') "femcod: "//prefix//".h5: the run of "// &
               deck_label(deck_path)//" is complete; nothing to restart"
            complete = .true.
            return
         end if
         if (.not. partial) then
            call set_error(st, STATUS_IO, prefix//".h5 holds the results of other inputs or options; "// &
               "--force replaces them, or give another -o")
            return
         end if
      end if
      if (have_checkpoint .and. .not. settings%restart .and. .not. settings%force) then
         call set_error(st, STATUS_IO, prefix//".ckpt.h5: the checkpoint of an interrupted run; continue it "// &
            "with --restart, or start afresh with --force")
         return
      end if
      call check_writable(prefix, st)
      if (st%code == 0 .and. .not. settings%force) then
         if (.not. (settings%restart .and. (have_checkpoint .or. partial .or. .not. path_exists(prefix//".h5")))) &
            call refuse_overwrite(prefix, requested_states(settings%solve), st)
      end if
      ! What is replaced (with --force, or as a restart's leftovers) must be femcod's; a
      ! checkpoint that --restart continues is checked whole by read_checkpoint.
      ! (Named arrays, not constructors in the call: gfortran's temporaries of derived types
      ! with allocatable components have corrupted the heap here, femcod-mpi 2026-11-26.)
      allocate(none(0), checkpoint(1))
      checkpoint(1)%s = prefix//".ckpt.h5"
      names = result_files(prefix, requested_states(settings%solve))
      if (st%code == 0) call guard_outputs(names, none, .true., OUTPUT_RESULT, st)
      if (st%code == 0 .and. .not. settings%restart) call guard_outputs(checkpoint, none, .true., OUTPUT_RESULT, st)
   end subroutine check_existing

   !> The progress and checkpoint observer of one run: what it aims at (contacts, the
   !> largest load), how its cost grows, what a step is called, where checkpoints go.
   subroutine configure_observer(self, prefix, problem, options, quiet)
      class(run_observer), intent(inout) :: self
      character(len=*), intent(in) :: prefix
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      logical, intent(in) :: quiet
      self%quiet = quiet
      self%target_contacts = problem%maxcont
      if (options%max_contacts > 0) self%target_contacts = min(options%max_contacts, problem%np**2)
      if (size(options%loads) > 0) self%target_load = maxval(options%loads)
      self%growth = merge(4.0_dp, 3.0_dp, options%solver == SOLVER_LEGACY)
      self%step_word = "event"
      if (options%solver == SOLVER_CG) then
         self%step_word = trim(merge("approach", "load    ", size(options%approaches) > 0))
         self%states = requested_states(options)
      end if
      self%checkpoint_path = prefix//".ckpt.h5"
   end subroutine configure_observer

   !> The result files of `prefix` (and its checkpoint and lock) may not be one of the
   !> input files, with or without --force.
   subroutine refuse_input_as_output(prefix, nloads, inputs, st)
      character(len=*), intent(in) :: prefix
      integer, intent(in) :: nloads
      type(string_type), intent(in) :: inputs(:)
      type(status_type), intent(inout) :: st
      type(string_type), allocatable :: names(:)
      integer :: m, i
      names = [result_files(prefix, nloads), string_type(prefix//".ckpt.h5"), string_type(prefix//".lock")]
      do m = 1, size(names)
         do i = 1, size(inputs)
            if (canonical_path(names(m)%s) == canonical_path(inputs(i)%s)) then
               call set_error(st, STATUS_USAGE, names(m)%s//" would replace the input "//inputs(i)%s// &
                  ": give another -o PREFIX")
               return
            end if
         end do
      end do
   end subroutine refuse_input_as_output

   !> A deck with its prefix locked: the checks of existing files, the solve, the results.
   subroutine run_locked(deck_path, prefix, settings, problem, inputs, files, pending, read_seconds, st)
      character(len=*), intent(in) :: deck_path, prefix
      type(run_settings), intent(in) :: settings
      type(contact_problem), intent(in) :: problem
      type(string_type), intent(in) :: inputs(:), files(:)
      !> The input files' digests, started while they were read (file_sha256_start).
      type(file_digest), intent(inout) :: pending(:)
      !> Wall seconds of reading the inputs.
      real(dp), intent(in) :: read_seconds
      type(status_type), intent(inout) :: st
      type(contact_result) :: res
      type(run_observer) :: observer
      type(incremental_state) :: resume
      type(state_maps), allocatable :: maps(:)
      type(run_info) :: info
      type(shear_model) :: shear
      character(len=:), allocatable :: fingerprint, started
      type(string_type), allocatable :: digests(:), warnings(:)
      logical :: resuming, ok, have_checkpoint, complete, interrupted
      type(status_type) :: stopped
      type(contact_options) :: solve_options
      integer(i8) :: held
      real(dp) :: t0, t1, digest_seconds
      integer :: k
      associate(options => settings%solve)
         ! Every input file's SHA-256, once: for /run and for the fingerprint.
         call wall_clock(t0)
         call input_digests(files, pending, digests)
         call wall_clock(t1)
         digest_seconds = t1 - t0
         fingerprint = run_fingerprint(problem, options, digests)
         call check_existing(deck_path, prefix, settings, fingerprint, have_checkpoint, complete, st)
         if (st%code /= 0 .or. complete) return
         call observer%configure(prefix, problem, options, settings%quiet)
         resuming = .false.
         if (settings%restart) then
            if (have_checkpoint) then
               call resume%init(problem, options)
               call read_checkpoint(observer%checkpoint_path, problem, options, resume, st)
               if (st%code == 0) call resume%rebuild(st)
               if (st%code /= 0 .and. index(st%message, observer%checkpoint_path) == 0) &
                  st%message = observer%checkpoint_path//": checkpoint refused: "//st%message
               if (st%code /= 0) return
               resuming = .true.
               if (.not. settings%quiet) write(error_unit, '(a)') "femcod: resuming "// &
                  deck_label(deck_path)//" from "//observer%checkpoint_path//" at step "//int_str(resume%step)//" ("// &
                  int_str(resume%n)//" contacts)"
            else if (.not. settings%quiet) then
               write(error_unit, '(a)') "femcod: no checkpoint "//observer%checkpoint_path//": starting "// &
                  deck_label(deck_path)//" from the beginning"
            end if
         else if (have_checkpoint) then
            ! --force: the old checkpoint is not this run's.
            call remove_file(prefix//".ckpt.h5")
         end if
         if (options%solver == SOLVER_CG .and. len(settings%wisdom) > 0) call load_wisdom(settings%wisdom, ok)
         started = local_time_iso()
         ! The solvers check their storage against what this run may still take; the
         ! summary's estimate is what the run holds now plus that storage.
         solve_options = options
         held = resident_bytes()
         solve_options%memory_available = available_memory()
         if (resuming) then
            call solve_contact(problem, solve_options, res, st, observer, resume)
         else
            call solve_contact(problem, solve_options, res, st, observer)
         end if
         if (res%estimated_peak_bytes > 0) res%estimated_peak_bytes = res%estimated_peak_bytes + held
         interrupted = st%code == STATUS_INTERRUPTED
         if (interrupted) then
            if (path_exists(observer%checkpoint_path) .and. observer%stored) then
               st%message = st%message//"; the state is in "//observer%checkpoint_path//" (continue with --restart)"
               return
            else if (res%stop_reason /= STOP_INTERRUPTED .or. .not. any(res%states%reached)) then
               st%message = st%message//"; nothing was written"
               return
            end if
            ! The requested states finished before the signal are written, as a partial run.
            stopped = st
            st = status_type()
         end if
         if (st%code == 0 .and. options%solver == SOLVER_CG .and. len(settings%wisdom) > 0) &
            call save_wisdom(settings%wisdom, st)
         if (st%code /= 0) return
         info%version = FEMCOD_VERSION
         info%solver = solver_name(options%solver)
         info%boundary = boundary_name(options%boundary)
         info%adhesion = law_name(options%adhesion)
         info%work = options%work
         info%range = options%range
         info%friction = options%shear
         info%tangential = options%tangential
         info%coulomb = options%friction
         info%beta = second_dundurs_constant(problem%young(1:2), problem%poisson(1:2))
         if (options%shear) then
            shear = run_shear_model(options)
            info%shear_strength = shear%tau0
            info%shear_slope = shear%alpha
            info%shear_cap = shear%tau_max
         end if
         info%options = settings%command_line
         info%figures = settings%figures
         info%command_line = "femcod run "//settings%command_line
         info%host = host_name()
         info%started = started
         info%finished = local_time_iso()
         info%scene = model_notes(problem, options)
         info%inputs = inputs
         info%fingerprint = fingerprint
         ! A partial run is not the run asked for: --restart runs it again.
         if (interrupted) info%fingerprint = fingerprint//PARTIAL_MARK
         info%digests = digests
         info%read_seconds = read_seconds
         info%digest_seconds = digest_seconds
         call wall_clock(t0)
         call load_maps(problem, res%states, maps, options%boundary == BOUNDARY_PERIODIC)
         call wall_clock(t1)
         info%maps_seconds = t1 - t0
         call write_results(prefix, problem, res, maps, info, st)
         if (st%code /= 0) return
         ! The set is replaced as a whole: what an earlier run left beside it goes, and the
         ! checkpoint has served its purpose.
         call remove_stale_results(prefix, res, settings%figures)
         warnings = run_warnings(options, res)
         do k = 1, size(warnings)
            write(error_unit, '(a)') "femcod: warning: "//warnings(k)%s
         end do
         if (.not. settings%quiet) call print_summary(deck_path, prefix, problem, options, res, maps)
         if (interrupted) then
            st = stopped
            st%message = st%message//"; the "//count_text(count(res%states%reached), "requested state")// &
               " finished before it are in "//prefix//".h5 and its companions (a partial run)"
         end if
      end associate
   end subroutine run_locked

   !> Remove what an earlier run of this prefix left beside the new set: pressure maps this
   !> run did not write (unreached states, --figures) or of loads beyond the new ones, a
   !> loads file when none were asked, the checkpoint.
   subroutine remove_stale_results(prefix, res, figures)
      character(len=*), intent(in) :: prefix
      type(contact_result), intent(in) :: res
      character(len=*), intent(in) :: figures
      integer :: k, nloads
      nloads = 0
      if (allocated(res%states)) nloads = size(res%states)
      ! The figures this run did not write (an unreached state, --figures), and those of
      ! states beyond its own.
      do k = 1, nloads
         if (.not. pressure_figure_wanted(res, k, figures)) call remove_file(prefix//".pressure_"//int_str(k)//".svg")
      end do
      k = nloads + 1
      do while (path_exists(prefix//".pressure_"//int_str(k)//".svg"))
         call remove_file(prefix//".pressure_"//int_str(k)//".svg")
         k = k + 1
      end do
      if (nloads == 0) call remove_file(prefix//".loads.csv")
      call remove_file(prefix//".ckpt.h5")
      call remove_file(prefix//".ckpt.h5.part")
   end subroutine remove_stale_results

   !> SHA-256 of what decides a run's results: the problem's label, grid and materials,
   !> the options that shape the results, and the SHA-256 of every input file (which
   !> fix the heights; hashing those digests instead of the 2 NP^2 heights again saves
   !> a pass over them).
   function run_fingerprint(problem, options, digests) result(hex)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      !> "FILE sha256 HEX" per input file (input_digests).
      type(string_type), intent(in) :: digests(:)
      character(len=64) :: hex
      character(len=:), allocatable :: text
      integer :: k, at
      text = problem%label//"|"//int_str(problem%np)//"|"//format_real(problem%pixel)//"|"// &
         int_str(problem%maxcont)//"|"//reals(problem%young)//reals(problem%poisson)//history_options(options)//"|"
      do k = 1, size(digests)
         ! The digest without the file's path: a moved input is the same input.
         at = index(digests(k)%s, " sha256 ", back=.true.)
         if (at > 0) then
            text = text//digests(k)%s(at + 8:)//"|"
         else
            text = text//"unreadable|"
         end if
      end do
      hex = sha256_hex(text)
   contains
      function reals(v) result(t)
         real(dp), intent(in) :: v(:)
         character(len=:), allocatable :: t
         integer :: m
         t = ""
         do m = 1, size(v)
            t = t//format_real(v(m))//","
         end do
         t = t//"|"
      end function reals
   end function run_fingerprint

   !> "FILE sha256 HEX" for each input file.
   subroutine input_digests(files, pending, digests)
      type(string_type), intent(in) :: files(:)
      type(file_digest), intent(inout) :: pending(:)
      type(string_type), allocatable, intent(out) :: digests(:)
      character(len=64) :: hex
      integer :: k
      allocate(digests(size(files)))
      do k = 1, size(files)
         hex = file_sha256_finish(pending(k))
         if (len_trim(hex) == 64) then
            digests(k)%s = files(k)%s//" sha256 "//hex
         else
            digests(k)%s = files(k)%s//" (unreadable)"
         end if
      end do
   end subroutine input_digests

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
   subroutine print_summary(deck_path, prefix, problem, options, res, maps)
      character(len=*), intent(in) :: deck_path, prefix
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(in) :: res
      type(state_maps), intent(in) :: maps(:)
      type(report_line), allocatable :: lines(:)
      type(cg_state_diagnostics) :: work
      integer :: k, last
      last = res%nsteps
      if (deck_path /= "") then
         write(output_unit, '(a)') "femcod run "//deck_path//" (solver "//solver_name(options%solver)//")"
      else
         ! Height files: the scene's label names them (femcod run --lower FILE ...).
         write(output_unit, '(a)') problem%label//" (solver "//solver_name(options%solver)//")"
      end if
      write(output_unit, '(a)') "  scene     : "//problem%label
      write(output_unit, '(a)') "              NP = "//int_str(problem%np)//", d = "//format_real(problem%pixel)// &
         " nm, E = "//sig_str(problem%young(1), 4)//" / "//sig_str(problem%young(2), 4)//" / "// &
         sig_str(problem%young(3), 4)//" GPa (lower / upper / contact)"
      if (options%solver == SOLVER_CG) then
         write(output_unit, '(a)') "  loads     : "//int_str(count(res%states%reached))//" of "// &
            int_str(size(res%states))//" solved"
      else
         write(output_unit, '(a)') "  steps     : "//int_str(last)//", stopped: "//stop_reason_text(res%stop_reason)
         if (last > 0) then
            write(output_unit, '(a)') "  last step : "//int_str(res%step_contacts(last))//" contacts up to load "// &
               sig_str(res%step_load(last), 6)//" nN (where the next contact closes), approach "// &
               sig_str(res%step_approach(last), 6)//" nm"
         end if
      end if
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         work = cg_work(res, k)
         write(output_unit, '(a)') "  at load   : "//sig_str(res%states(k)%load, 6)//" nN: approach "// &
            sig_str(res%states(k)%approach, 6)//" nm"//trim(bound_text(work%approach_bound))//", "// &
            int_str(res%states(k)%contacts)//" contacts ("// &
            sig_str(res%states(k)%contacts*problem%pixel**2, 4)//" nm^2), max pressure "// &
            sig_str(res%states(k)%max_pressure, 4)//" GPa"
         call print_patches(maps(k)%patches)
         if (options%plastic) write(output_unit, '(a)') "              "//int_str(res%states(k)%n_plastic)// &
            " of them plastic (at the hardness "//sig_str(options%hardness, 4)//" GPa), plastic volume "// &
            sig_str(res%states(k)%plastic_volume, 4)//" nm^3"
         if (options%tangential) call print_tangential(res%states(k), problem%pixel)
         if (options%shear) write(output_unit, '(a)') "              friction "// &
            sig_str(res%states(k)%friction, 6)//" nN, coefficient "// &
            sig_str(friction_coefficient(res%states(k)%friction, res%states(k)%load, res%states(k)%contacts), 6)//" (shear model)"
         if (options%adhesion /= LAW_HARD_WALL) then
            write(output_unit, '(a)') "              "//int_str(res%states(k)%attractive)//" pixels off contact within the "// &
               "range ("//sig_str(res%states(k)%attractive*problem%pixel**2, 4)//" nm^2), load off contact "// &
               sig_str(res%states(k)%attractive_load, 4)//" nN, mean gap "//sig_str(res%states(k)%mean_gap, 4)//" nm"
            if (res%states(k)%jump /= 0 .and. k > 1) write(output_unit, '(a)') "              "// &
               trim(merge("contact appears ", "contact vanishes", res%states(k)%jump > 0))//" since the approach "// &
               sig_str(res%states(k - 1)%approach, 6)//" nm ("//int_str(res%states(k - 1)%contacts)//" -> "// &
               int_str(res%states(k)%contacts)//" contact pixels, load "//sig_str(res%states(k - 1)%load, 4)// &
               " -> "//sig_str(res%states(k)%load, 4)//" nN)"
         end if
      end do
      if (options%adhesion /= LAW_HARD_WALL) write(output_unit, '(a)') "  adhesion  : least load "// &
         sig_str(minval(res%states%load, mask=res%states%reached), 6)//" nN over the approaches (the pull-off force "// &
         "where they pass it)"
      if (options%solver == SOLVER_CG) then
         write(output_unit, '(a)') "  wall time : "//sig_str(res%wall_seconds, 3)//" s"
      else
         write(output_unit, '(a)') "  wall time : "//sig_str(res%wall_seconds, 3)//" s in total, "// &
            sig_str(res%wall_seconds/max(last, 1), 3)//" s per step"
      end if
      write(output_unit, '(a)') "  written   : "//prefix//".h5, .xdmf, .summary.json, .history.csv, .contacts.csv, "// &
         ".load_approach.svg, .area_load.svg"//trim(merge(", .loads.csv, .pressure_<k>.svg", &
         repeat(" ", 31), size(res%states) > 0))
      ! The solver's own account last.
      lines = report_lines(problem, options, res)
      do k = 1, size(lines)
         write(output_unit, '(a)') "  "//lines(k)%label//repeat(" ", max(0, 10 - len(lines(k)%label)))//": "// &
            lines(k)%text
      end do
   end subroutine print_summary

   !> The patches line of the summary: the 4- and 8-connected counts, the largest patch
   !> and the perimeter-area exponent.
   subroutine print_patches(patches)
      type(contact_patches), intent(in) :: patches
      real(dp) :: exponent, prefactor
      character(len=:), allocatable :: fit
      call perimeter_area_fit(patches%area4, patches%perimeter4, exponent, prefactor)
      fit = ""
      if (exponent == exponent) fit = ", perimeter ~ area^"//sig_str(exponent, 3)
      write(output_unit, '(a)') "              patches "//int_str(patches%count4)//" (4-connected), "// &
         int_str(patches%count8)//" (8-connected), the largest "//int_str(maxval([0, patches%area8]))// &
         " pixels"//fit
   end subroutine print_patches

   !> A state's tangential step in the summary: the force and shift along x, the stick
   !> area, or gross sliding.
   subroutine print_tangential(s, pixel)
      type(load_state), intent(in) :: s
      real(dp), intent(in) :: pixel
      integer :: stick
      if (.not. allocated(s%stick)) then
         write(output_unit, '(a)') "              tangential: none (no contact carries it)"
         return
      end if
      stick = count(s%stick)
      if (s%sliding) then
         write(output_unit, '(a)') "              tangential "//sig_str(s%tangential_force(1), 6)//" nN: gross "// &
            "sliding, every contact at mu p (shift "//sig_str(s%tangential_shift(1), 6)//" nm at the onset)"
      else
         write(output_unit, '(a)') "              tangential "//sig_str(s%tangential_force(1), 6)//" nN, shift "// &
            sig_str(s%tangential_shift(1), 6)//" nm; "//int_str(stick)//" of "//int_str(size(s%stick))// &
            " contacts stick ("//sig_str(stick*pixel**2, 4)//" nm^2, "// &
            sig_str(100*real(stick, dp)/size(s%stick), 4)//" %); "//int_str(s%tangential_iterations)// &
            " iterations, residual "//sig_str(s%tangential_residual, 2)
      end if
   end subroutine print_tangential

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
         estimate = ", about "//sig_str(left, 2)//" s left (cost ~ contacts^"//int_str(nint(self%growth))//")"
      end if
      if (.not. allocated(self%step_word)) self%step_word = "event"
      if (self%step_word == "event") then
         write(error_unit, '(a)') "femcod: event "//int_str(step)//", "//int_str(contacts)//" contacts, load "// &
            sig_str(load, 5)//" nN, "//sig_str(elapsed, 3)//" s elapsed"//estimate
      else
         write(error_unit, '(a)') "femcod: "//self%step_word//" "//int_str(step)//" of "//int_str(self%states)// &
            " solved, "//int_str(contacts)//" contacts, load "//sig_str(load, 5)//" nN, "//sig_str(elapsed, 3)// &
            " s elapsed"
      end if
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
      self%stored = self%stored .or. st%code == 0
      if (st%code /= 0 .and. .not. self%warned) then
         write(error_unit, '(a)') "femcod: warning: checkpoint not written: "//st%message
         flush(error_unit)
         self%warned = .true.
      end if
   end subroutine store_checkpoint

   !> A stop signal (SIGTERM, SIGINT, SIGUSR1) has arrived.
   logical function signal_arrived(self)
      class(run_observer), intent(inout) :: self
      signal_arrived = stop_signal() /= 0
   end function signal_arrived

   !> " (+- B nm)" after an approach the solver bounds (B >= 0), "" otherwise.
   function bound_text(bound) result(text)
      real(dp), intent(in) :: bound
      character(len=:), allocatable :: text
      text = ""
      if (bound >= 0) text = " (+- "//sig_str(bound, 2)//" nm)"
   end function bound_text

   !> How a deck is named in messages.
   function deck_label(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      name = path
      if (path == "") name = "the height files"
   end function deck_label

   !> A directory's name without its trailing slashes ("/" stays "").
   pure function without_slash(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      integer :: n
      n = len(path)
      do while (n > 0)
         if (path(n:n) /= "/") exit
         n = n - 1
      end do
      name = path(1:n)
   end function without_slash
end module femcod_run
