!> `femcod run`'s arguments: the option table (run_table, from which --help is printed),
!> the settings they give (run_settings, with the solver's contact_options from the
!> option table of model/femcod_solver_options), and the rules that refuse what does not
!> apply, before any file is read. No I/O but the help.
module femcod_run_options
   use, intrinsic :: iso_fortran_env, only: output_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_strings, only: string_type, int_str
   use femcod_files, only: path_is_directory, default_prefix, file_part, canonical_path
   use femcod_generate, only: scene_spec
   use femcod_heights, only: is_height_file
   use femcod_solver_options, only: contact_options, validate_options, SOLVER_CG, LAW_HARD_WALL, solver_name, &
      OPTION_NAMES, option_field
   use femcod_shear_model, only: friction_coefficient
   use femcod_results, only: FIGURES_AUTO_LIMIT, HISTORY_HEADER, LOADS_HEADER, CONTACTS_HEADER, FRICTION_COLUMNS, &
      PATCH_COLUMNS
   use femcod_help, only: print_lines
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, scene_options, flag_option, &
      real_option, integer_option, text_option, choice_option, real_list_option, get_option, option_given, &
      refuse_options
   implicit none
   private
   public :: run_table, run_settings, parse_run_arguments, run_help, assign_prefixes, deck_label, without_slash

   !> Everything `femcod run` was asked, after parsing.
   type :: run_settings
      !> The decks, in order ("" for the one scene of --lower/--upper), and the output
      !> prefix of each.
      type(string_type), allocatable :: decks(:), prefixes(:)
      !> Output prefix ("": each deck's name), directory of the outputs ("": here), FFTW
      !> wisdom file ("": none).
      character(len=:), allocatable :: prefix, outdir, wisdom
      logical :: quiet = .false., force = .false., restart = .false.
      !> Which states get their map figures (--figures all|last|none|auto).
      character(len=:), allocatable :: figures
      !> The scene of --lower/--upper (kind "matrix").
      type(scene_spec) :: scene
      logical :: from_files = .false.
      !> The solver and its options.
      type(contact_options) :: solve
      !> The arguments as given, for the run record.
      character(len=:), allocatable :: command_line
   end type run_settings

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
         choice_option("--figures", "auto|all|last|none", "which states get their map figures PREFIX.pressure_<k>.svg, "// &
            ".gap_<k>.svg (and .plastic_<k>.svg, .stick_slip_<k>.svg with --plastic, the tangential step) "// &
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
         real_option("--tangential-tol", "T", "the tangential step stops when its gradient mapping is below T of "// &
            "the shift (default 1e-8; --tol is the normal solve's)", lower=0.0_dp, closed="()"), &
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
         "run; the exit code is that of the first failure, and a final summary lists the failures (each", &
         "also as PREFIX.failed.json, its deck, exit code and message, for `femcod report DIR`).", &
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
         "         PREFIX.load_approach.svg, PREFIX.area_load.svg, PREFIX.pressure_<k>.svg and the", &
         "         other map figures of --figures (doc/results.md).", &
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
      else if (option_given(parsed, "--tangential-tol") .and. .not. settings%solve%tangential) then
         call set_error(status, STATUS_USAGE, "--tangential-tol T is the tolerance of a tangential step: add "// &
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
end module femcod_run_options
