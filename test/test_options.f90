!> The option parser (cli/femcod_options) and the commands' tables: values, ranges,
!> choices, lists, modes, help. Every expected message is the parser's documented form
!> ("OPTION expects WHAT, found 'VALUE'", "OPTION applies TEXT").
module test_options
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: string_type
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, flag_option, real_option, &
      integer_option, text_option, choice_option, real_list_option, integer_list_option, get_option, option_given, &
      refuse_options
   use femcod_run_options, only: run_table, run_settings, parse_run_arguments
   use femcod_cli, only: run_femcod, mkdeck_table, parse_mkdeck_arguments
   use femcod_generate, only: scene_spec
   use test_support, only: scratch_path, read_text
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   use femcod_solver_options, only: SOLVER_CG, OPTION_NAMES, OPTION_KEYS, IN_HISTORY, contact_options, history_options
   implicit none
   private
   public :: collect_options

contains

   subroutine collect_options(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("values of every kind, aliases, positionals", test_values), &
         new_unittest("ranges, choices, lists and missing values are refused with their expectation", test_refused), &
         new_unittest("an option outside its mode is refused", test_modes), &
         new_unittest("run: the arguments land in the solver options", test_run_settings), &
         new_unittest("run: every row of the solver's option table is in run's table and history", test_option_keys), &
         new_unittest("run: scene options with a deck, cg options with another solver: exit 2", test_run_refusals), &
         new_unittest("mkdeck: a kind's options with another kind: exit 2", test_mkdeck), &
         new_unittest("help lists every option of a table", test_help) &
         ]
   end subroutine collect_options

   function table() result(t)
      type(option_spec), allocatable :: t(:)
      t = [flag_option("--quiet", "q", alias="-q"), &
         real_option("--pixel", "D", "pixel", lower=0.0_dp, closed="()"), &
         real_option("--poisson", "NU", "ratio", lower=-1.0_dp, upper=0.5_dp, closed="()"), &
         integer_option("--np", "N", "side", lower=1), &
         text_option("--output", "PREFIX", "prefix", alias="-o"), &
         choice_option("--rigid", "upper|lower|none", "rigid"), &
         real_list_option("--loads", "F", "loads", lower=0.0_dp), &
         real_list_option("--exponents", "E", "three", length=3), &
         integer_list_option("--levels", "L", "levels", lower=1), &
         real_option("--young", "E", "modulus", lower=0.0_dp, closed="()", mode="heights"), &
         real_option("--tol", "T", "tolerance", lower=0.0_dp, closed="()", mode="cg")]
   end function table

   function args_of(text) result(args)
      character(len=*), intent(in) :: text
      type(string_type), allocatable :: args(:)
      integer :: start, k
      allocate(args(0))
      start = 1
      do k = 1, len(text) + 1
         if (k > len(text)) then
            if (k > start) args = [args, string_type(text(start:k - 1))]
         else if (text(k:k) == " ") then
            if (k > start) args = [args, string_type(text(start:k - 1))]
            start = k + 1
         end if
      end do
   end function args_of

   subroutine test_values(error)
      type(error_type), allocatable, intent(out) :: error
      type(parsed_options) :: parsed
      type(status_type) :: status
      real(dp) :: pixel
      real(dp), allocatable :: loads(:)
      integer, allocatable :: levels(:)
      character(len=:), allocatable :: out, rigid
      integer :: np
      logical :: quiet
      call parse_options(table(), args_of("a.deck -q --pixel 2.5 --np 7 -o x --rigid none --loads 1,2e3 "// &
         "--levels 4,2 b.deck"), parsed, status)
      call check(error, status%code, 0, "parsed")
      if (allocated(error)) return
      pixel = 0
      np = 0
      quiet = .false.
      out = ""
      rigid = ""
      call get_option(parsed, "--pixel", pixel)
      call get_option(parsed, "--np", np)
      call get_option(parsed, "--quiet", quiet)
      call get_option(parsed, "--output", out)
      call get_option(parsed, "--rigid", rigid)
      call get_option(parsed, "--loads", loads)
      call get_option(parsed, "--levels", levels)
      call check(error, pixel == 2.5_dp .and. np == 7 .and. quiet .and. out == "x" .and. rigid == "none", &
         "scalars")
      if (allocated(error)) return
      call check(error, size(loads) == 2 .and. all(loads == [1.0_dp, 2.0e3_dp]) .and. all(levels == [4, 2]), "lists")
      if (allocated(error)) return
      call check(error, size(parsed%positional) == 2 .and. .not. option_given(parsed, "--young"), "positionals")
      if (allocated(error)) return
      call check(error, parsed%positional(1)%s == "a.deck" .and. parsed%positional(2)%s == "b.deck", "their order")
   end subroutine test_values

   subroutine test_refused(error)
      type(error_type), allocatable, intent(out) :: error
      call expect("--pixel 0", "--pixel expects a number > 0, found '0'")
      if (allocated(error)) return
      call expect("--poisson 0.5", "--poisson expects a number in (-1, 0.5), found '0.5'")
      if (allocated(error)) return
      call expect("--np 2.5", "--np expects an integer >= 1, found '2.5'")
      if (allocated(error)) return
      call expect("--rigid top", "--rigid expects one of upper, lower, none, found 'top'")
      if (allocated(error)) return
      call expect("--loads 1,-2", "--loads expects numbers >= 0, comma-separated, found '1,-2'")
      if (allocated(error)) return
      call expect("--exponents 1,2", "--exponents expects 3 numbers, comma-separated, found '1,2'")
      if (allocated(error)) return
      ! A repeated option is refused, alias or not (issue 35: the last one used to win).
      call expect("--np 7 --np 9", "option --np is given twice (--np); give it once")
      if (allocated(error)) return
      call expect("-o a --output b", "option --output is given twice (--output or -o); give it once")
      if (allocated(error)) return
      call expect("-q --quiet", "option --quiet is given twice (--quiet or -q); give it once")
      if (allocated(error)) return
      call expect("--pixel nan", "--pixel expects a number > 0, found 'nan'")
      if (allocated(error)) return
      call expect("--frobnicate 1", "unknown option --frobnicate")
      if (allocated(error)) return
      call expect("a.deck --pixel", "option --pixel needs a value (a number > 0)")
   contains
      subroutine expect(text, message)
         character(len=*), intent(in) :: text, message
         type(parsed_options) :: parsed
         type(status_type) :: status
         call parse_options(table(), args_of(text), parsed, status)
         call check(error, status%code, 2, text//": usage error")
         if (allocated(error)) return
         call check(error, status%message, message)
      end subroutine expect
   end subroutine test_refused

   subroutine test_modes(error)
      type(error_type), allocatable, intent(out) :: error
      type(parsed_options) :: parsed
      type(status_type) :: status
      call parse_options(table(), args_of("a.deck --young 5 --tol 1e-9"), parsed, status)
      call refuse_options(parsed, "cg|heights", "", status)
      call check(error, status%code, 0, "both modes in force")
      if (allocated(error)) return
      call refuse_options(parsed, "cg", "heights=to height files", status)
      call check(error, status%code == 2 .and. status%message == "--young applies to height files", &
         "a mode not in force: "//status%message)
      if (allocated(error)) return
      status = status_type()
      call refuse_options(parsed, "heights", "", status)
      call check(error, status%code == 2 .and. status%message == "--tol applies to cg only", &
         "the default text names the mode: "//status%message)
   end subroutine test_modes

   subroutine test_run_settings(error)
      type(error_type), allocatable, intent(out) :: error
      type(run_settings) :: settings
      type(status_type) :: status
      call parse_run_arguments(args_of("a.deck --solver cg --loads 1,2 --tol 1e-9 --max-iterations 50 --hardness 5 "// &
         "-o options_out"), settings, status)
      call check(error, status%code, 0, "parsed")
      if (allocated(error)) return
      associate(o => settings%solve)
         call check(error, o%solver == SOLVER_CG .and. all(o%loads == [1.0_dp, 2.0_dp]) .and. o%cg%tol == 1.0e-9_dp .and. &
            o%cg%max_iterations == 50 .and. o%hardness == 5 .and. settings%prefix == "options_out", "cg options")
         if (allocated(error)) return
      end associate
      call parse_run_arguments(args_of("--lower h.txt --pixel 2 --young 70 --poisson 0.3 --rigid-factor 1e6 "// &
         "--maxcont 9 --event-search fft --checkpoint-interval 0"), settings, status)
      call check(error, status%code, 0, "heights parsed")
      if (allocated(error)) return
      associate(sc => settings%scene)
         call check(error, settings%from_files .and. sc%matrix_file == "h.txt" .and. sc%shape_on == "lower" .and. &
            sc%pixel == 2 .and. sc%young == 70 .and. sc%poisson == 0.3_dp .and. sc%rigid_factor == 1.0e6_dp .and. &
            sc%maxcont == 9 .and. settings%prefix == "h", "height-file scene")
         if (allocated(error)) return
      end associate
      call check(error, settings%solve%event_search == "fft" .and. settings%solve%checkpoint_interval == 0, &
         "incremental options")
   end subroutine test_run_settings

   !> The solver's option table (model/femcod_solver_options' OPTION_NAMES and OPTION_KEYS,
   !> from which run's settings, history_options and the libraries' accepted names come):
   !> each name is an option of `femcod run`, each key in the history a field of
   !> history_options, once.
   subroutine test_option_keys(error)
      type(error_type), allocatable, intent(out) :: error
      type(option_spec), allocatable :: table(:)
      type(contact_options) :: defaults
      character(len=:), allocatable :: history
      integer :: k, m
      table = run_table()
      history = "; "//history_options(defaults)
      call check(error, size(OPTION_NAMES) == size(OPTION_KEYS) .and. size(OPTION_KEYS) == size(IN_HISTORY), &
         "one key and one history flag per name")
      if (allocated(error)) return
      do k = 1, size(OPTION_NAMES)
         if (len_trim(OPTION_NAMES(k)) > 0) then
            call check(error, any([(table(m)%name == trim(OPTION_NAMES(k)), m = 1, size(table))]), &
               trim(OPTION_NAMES(k))//" is an option of femcod run")
            if (allocated(error)) return
         end if
         if (IN_HISTORY(k)) then
            m = index(history, "; "//trim(OPTION_KEYS(k))//"=")
            call check(error, m > 0 .and. index(history(m + 1:), "; "//trim(OPTION_KEYS(k))//"=") == 0, &
               trim(OPTION_KEYS(k))//" is one field of history_options: "//history)
            if (allocated(error)) return
         end if
      end do
   end subroutine test_option_keys

   !> An option that does not apply to the run is a usage error (exit 2), never accepted
   !> and ignored: scene options with a deck, each solver's own with another solver.
   subroutine test_run_refusals(error)
      type(error_type), allocatable, intent(out) :: error
      call expect("run input/sphere_d1.deck --young 5 --pixel 3 --quiet", "applies to height files")
      if (allocated(error)) return
      call expect("run input/sphere_d1.deck --tol 1e-9 --quiet", "applies to --solver cg only")
      if (allocated(error)) return
      call expect("run input/sphere_d1.deck --solver cg --loads 1 --max-contacts 5 --quiet", &
         "applies to the event solvers")
      if (allocated(error)) return
      call expect("run input/sphere_d1.deck --solver legacy --event-search fft --quiet", &
         "applies to the incremental solver only")
   contains
      subroutine expect(text, fragment)
         character(len=*), intent(in) :: text, fragment
         type(run_settings) :: settings
         type(status_type) :: status
         integer :: code
         call parse_run_arguments(args_of(text(5:)), settings, status)
         call check(error, status%code == 2 .and. index(status%message, fragment) > 0, text//": "//status%message)
         if (allocated(error)) return
         call run_femcod(args_of(text), code)
         call check(error, code, 2, text//": exit code")
      end subroutine expect
   end subroutine test_run_refusals

   subroutine test_mkdeck(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_spec) :: spec
      type(status_type) :: status
      character(len=:), allocatable :: output, verification, dir
      call parse_mkdeck_arguments(args_of("self-affine --np 8 --pixel 2 --hurst 0.5 --rms 2 --seed 4 -o x.deck"), spec, &
         output, verification, dir, status)
      call check(error, status%code == 0 .and. spec%kind == "self-affine" .and. spec%np == 8 .and. spec%hurst == 0.5_dp &
         .and. spec%rms == 2 .and. spec%seed == 4 .and. output == "x.deck", "a self-affine spec")
      if (allocated(error)) return
      call parse_mkdeck_arguments(args_of("self-affine --np 8 --pixel 2 --radius 3 -o x.deck"), spec, output, &
         verification, dir, status)
      call check(error, status%code == 2 .and. status%message == "--radius applies to circle-punch, sphere only", &
         "a sphere's option with a self-affine scene: "//status%message)
      if (allocated(error)) return
      status = status_type()
      call parse_mkdeck_arguments(args_of("matrix --file h.txt --np 8 --pixel 2 -o x.deck"), spec, output, &
         verification, dir, status)
      call check(error, status%code == 2 .and. index(status%message, "--np applies to") == 1, &
         "--np with a matrix: "//status%message)
   end subroutine test_mkdeck

   !> The help lines are made from the tables, so every option of run and mkdeck appears:
   !> in the text `femcod run --help` prints (this test program run as femcod), each option
   !> starts a line of its own, not only a mention in another's help.
   subroutine test_help(error)
      type(error_type), allocatable, intent(out) :: error
      type(option_spec), allocatable :: t(:)
      type(string_type), allocatable :: lines(:)
      character(len=:), allocatable :: all
      character(len=*), parameter :: modes(6) = [character(len=11) :: "", "event", "incremental", "cg", "heights", "x"]
      integer :: k, m
      t = run_table()
      all = ""
      do m = 1, size(modes)
         lines = option_help(t, trim(modes(m)))
         do k = 1, size(lines)
            all = all//lines(k)%s//new_line("a")
         end do
      end do
      do k = 1, size(t)
         call check(error, index(all, "  "//t(k)%name) > 0 .or. index(all, ", "//t(k)%name) > 0, &
            "run --help lists "//t(k)%name)
         if (allocated(error)) return
      end do
      block
         character(len=:), allocatable :: self, printed, path
         integer :: length, code
         call get_command_argument(0, length=length)
         allocate(character(len=length) :: self)
         call get_command_argument(0, self)
         path = scratch_path("run-help.txt")
         call execute_command_line(self//" --femcod run --help > "//path, exitstat=code)
         call check(error, code, 0, "femcod run --help")
         if (allocated(error)) return
         printed = new_line("a")//read_text(path)
         do k = 1, size(t)
            call check(error, index(printed, new_line("a")//"  "//t(k)%name//" ") > 0 .or. &
               index(printed, new_line("a")//"  "//t(k)%name//new_line("a")) > 0 .or. &
               (len(t(k)%alias) > 0 .and. index(printed, new_line("a")//"  "//t(k)%alias//", "//t(k)%name) > 0), &
               "femcod run --help has a line for "//t(k)%name)
            if (allocated(error)) return
         end do
      end block
      t = mkdeck_table()
      call check(error, size(t) > 20, "mkdeck has its table: "//to_string(size(t)))
   end subroutine test_help
end module test_options
