!> `femcod bench`: speed against error, one table. Every number is measured in this run.
module femcod_bench
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem, THESIS_RIGID_FACTOR, RIGID_FACTOR, verification_spec, &
      paraboloid_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, flag_option, real_option, &
      integer_option, text_option, choice_option, real_list_option, integer_list_option, get_option, option_given
   use femcod_thesis, only: TABLE_4_1_APPROACH, TABLE_4_2_APPROACH
   use femcod_analytic, only: segedin_sphere, maugis_pull_off
   use femcod_scene, only: initial_gaps
   use femcod_wisdom, only: load_wisdom, save_wisdom
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, &
      convolution_free
   use femcod_love, only: offset_table
   use femcod_love_periodic, only: periodic_love_spectrum
   use femcod_random, only: random_stream, seed_stream, uniform
   use femcod_clock, only: wall_clock
   use femcod_deck, only: write_deck
   use femcod_files, only: write_file, file_part, path_exists, canonical_path
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_read, h5_create, h5_write
   use femcod_svg, only: svg_pressure_map, svg_series, add_series, svg_multi_plot
   use femcod_resolution_study, only: level_deck
   use femcod_resolution, only: mccool_surface, mccool_area, mccool_parameters, composite_modulus
   use femcod_love, only: love_influence, surface_compliance
   use femcod_spring, only: spring_stiffness
   use femcod_scene, only: flip_upper
   use femcod_sort, only: merge_sort_index
   use femcod_adhesion, only: pixel_stiffness_ratio
   implicit none
   private
   public :: bench_command

   !> The benchmark surface's side: 5 um.
   real(dp), parameter :: BENCH_LENGTH = 5000


contains

   subroutine bench_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(contact_problem) :: rough, deck
      type(scene_spec) :: spec
      type(status_type) :: status
      type(contact_result) :: inc, leg
      type(contact_options) :: options
      type(parsed_options) :: parsed
      integer :: legacy_contacts, n, k
      logical :: full
      real(dp), allocatable :: cg_loads(:), cg_approach(:)
      real(dp) :: err, peak
      code = 0
      if (size(args) > 0) then
         if (args(1)%s == "cg") then
            call bench_cg(args(2:), code)
            return
         end if
         if (args(1)%s == "convolution") then
            call bench_convolution(args(2:), code)
            return
         end if
         if (args(1)%s == "io") then
            call bench_io(args(2:), code)
            return
         end if
         if (args(1)%s == "periodic") then
            call bench_periodic(args(2:), code)
            return
         end if
         if (args(1)%s == "frontier") then
            call bench_frontier(args(2:), code)
            return
         end if
         if (args(1)%s == "adhesion") then
            call bench_adhesion(args(2:), code)
            return
         end if
         if (args(1)%s == "mpi") then
            call bench_mpi(args(2:), code)
            return
         end if
      end if
      legacy_contacts = 300
      full = .false.
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod bench [--full] [--legacy-contacts N]", &
            "       femcod bench cg [--np LIST] [--contact LIST] [--tol T] [--peers PYTHON]  (--help for more)", &
            "       femcod bench convolution [--np LIST] [--repeat N]  (--help for more)", &
            "       femcod bench io [--np LIST] [--dir DIR]  (--help for more)", &
            "       femcod bench periodic [--np LIST] [--contact LIST]  (--help for more)", &
            "       femcod bench frontier [--np N] [--contact LIST] [--svg FILE]  (--help for more)", &
            "       femcod bench adhesion [--full]  (--help for more)", &
            "       femcod bench mpi [--np LIST] [--ranks LIST]  (--help for more; needs femcod-mpi)", &
            "Times the solvers and prints one table: problem, NP, contacts, solver, wall time, time per", &
            "event, peak memory (resident, per case), error against the reference. The rough surface:", &
            "self-affine, H = 0.8, rms 3 nm, 5 um square, 512 x 512, E = 200 GPa, nu = 0.25, against a", &
            "rigid flat (seed 1).", ""
         call print_lines(option_help(bench_table(), ""))
         write(output_unit, '(a)') "Run it with the release build: fpm run --profile release -- bench"
         return
      end if
      if (.not. bench_arguments(bench_table(), args, "femcod bench", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--full", full)
      call get_option(parsed, "--legacy-contacts", legacy_contacts)

      spec%kind = "self-affine"
      spec%np = 512
      spec%pixel = 5000.0_dp/512
      spec%hurst = 0.8_dp
      spec%rms = 3
      spec%seed = 1
      spec%shape_on = "lower"
      spec%rigid = "upper"
      ! The thesis' rigid factor 1e5, as in its 121-hour run: the legacy solver is then
      ! accurate to ~1e-10 and the comparison of the two solvers measures them, not the
      ! penalty's round-off (doc/stability.md).
      spec%rigid_factor = THESIS_RIGID_FACTOR
      spec%label = "bench"
      spec%matrix_file = ""
      spec%maxcont = 512*512/20
      call build_problem(spec, rough, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod bench: "//status%message
         code = status%code
         return
      end if

      write(output_unit, '(a)') "| problem | NP | contacts | solver | wall (s) | per event (ms) | peak RSS (MB) "// &
         "| error | reference |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|"

      ! Rough surface: incremental against legacy over the first contacts. The legacy
      ! candidate list (Appendix B) can miss a contact and take it late; the comparison
      ! counts the events that agree before the first such difference.
      options%max_contacts = legacy_contacts
      allocate(options%loads(0))
      call reset_peak()
      call solve_with("incremental", rough, options, inc)
      peak = peak_mb()
      call reset_peak()
      call solve_with("legacy", rough, options, leg)
      ! Contacts in order of joining: the first pixel where the two lists differ.
      n = 0
      do k = 1, min(size(inc%contact_i), size(leg%contact_i))
         if (inc%contact_i(k) /= leg%contact_i(k) .or. inc%contact_j(k) /= leg%contact_j(k)) exit
         n = k
      end do
      ! Steps whose closing contact lies within that common prefix must agree.
      err = 0
      do k = 2, min(inc%nsteps, leg%nsteps)
         if (leg%step_contacts(k) + 1 > n .or. inc%step_contacts(k) + 1 > n) exit
         err = max(err, abs(inc%step_load(k) - leg%step_load(k))/leg%step_load(k))
      end do
      call row("self-affine 5 um", 512, inc, "incremental", err, "legacy: first "//int_str(n)// &
         " contacts identical, max rel. load diff. before; legacy took "//int_str(leg%missed_during_run)// &
         " contacts late, its final check found "//int_str(leg%missed_final_check), peak)
      call row("self-affine 5 um", 512, leg, "legacy", err, "incremental, as above", peak_mb())

      allocate(cg_loads(merge(2, 1, full)), cg_approach(merge(2, 1, full)))
      do k = 1, merge(2, 1, full)
         options%max_contacts = 2621*merge(1, 5, k == 1)
         call reset_peak()
         call solve_with("incremental", rough, options, inc)
         call row("self-affine 5 um, to "//int_str(merge(1, 5, k == 1))//" %", 512, inc, "incremental", &
            max(inc%final_check_difference, inc%max_penetration), "fresh solve of the final active set", peak_mb())
         ! Inside the last step (response linear there): the fixed-load solver's target.
         cg_loads(k) = (inc%step_load(inc%nsteps - 1) + inc%step_load(inc%nsteps))/2
         cg_approach(k) = (inc%step_approach(inc%nsteps - 1) + inc%step_approach(inc%nsteps))/2
      end do
      ! The fixed-load solver at the same loads (warm-started from one load to the next).
      options%max_contacts = 0
      options%loads = cg_loads
      options%cg%tol = 1.0e-8_dp
      options%cg%max_iterations = 5000
      call reset_peak()
      call solve_with("cg", rough, options, inc)
      call row("self-affine 5 um, at the "//trim(merge("1 and 5 % loads", "1 % load       ", full)), 512, inc, "cg", &
         maxval(abs(inc%states%approach - cg_approach)/cg_approach), "event-exact approach at the same loads; "// &
         int_str(sum(inc%states%iterations))//" iterations in all, residual "// &
         real_str(maxval(inc%states%residual), 2), peak_mb())

      ! Verification decks against their analytic or thesis values.
      if (allocated(options%loads)) deallocate(options%loads)
      options%max_contacts = 0
      call verification_row("circle_punch_d9", 1.0_dp, TABLE_4_1_APPROACH(3), "Table 4.1 approach "// &
         real_str(TABLE_4_1_APPROACH(3), 3)//" nm")
      call verification_row("square_punch_n27", 1.0_dp, TABLE_4_2_APPROACH(4), "Table 4.2 approach "// &
         real_str(TABLE_4_2_APPROACH(4), 3)//" nm")
      call verification_row("sphere_d05", 18000.0_dp, segedin(18000.0_dp), "Segedin approach at 18000 nN")
   contains
      subroutine verification_row(name, load, reference, what)
         character(len=*), intent(in) :: name, what
         real(dp), intent(in) :: load, reference
         type(scene_spec) :: verification
         ! The deck of input/, built in memory: the bench runs from any directory.
         call verification_spec(name, verification, status)
         call build_problem(verification, deck, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench: "//status%message
            return
         end if
         options%loads = [load]
         call reset_peak()
         call solve_with("incremental", deck, options, inc)
         call row(name, deck%np, inc, "incremental", abs(inc%states(1)%approach/reference - 1), what, peak_mb())
         call reset_peak()
         call solve_with("legacy", deck, options, leg)
         call row(name, deck%np, leg, "legacy", abs(leg%states(1)%approach/reference - 1), what, peak_mb())
      end subroutine verification_row

      !> One solver through the dispatcher; a failure is reported and the table goes on.
      subroutine solve_with(solver, problem, opts, res)
         character(len=*), intent(in) :: solver
         type(contact_problem), intent(in) :: problem
         type(contact_options), intent(inout) :: opts
         type(contact_result), intent(out) :: res
         opts%solver = solver
         call solve_contact(problem, opts, res, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench: "//solver//": "//status%message
            status = status_type()
         end if
      end subroutine solve_with
   end subroutine bench_command

   !> The options of `femcod bench`.
   function bench_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [flag_option("--full", "add the run to 5 % contact (minutes)"), &
         integer_option("--legacy-contacts", "N", "how far the legacy solver runs on the rough surface (default 300)", &
            lower=1)]
   end function bench_table

   !> The options of `femcod bench cg`.
   function bench_cg_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_list_option("--np", "N1,...", "grid sizes (default 512,1024)", lower=2), &
         real_list_option("--contact", "F1,...", "contact fractions in percent (default 1,5,10)", lower=0.0_dp, &
            upper=100.0_dp, closed="(]"), &
         real_option("--tol", "T", "the cg tolerance (default 1e-8)", lower=0.0_dp, closed="()"), &
         text_option("--peers", "PYTHON", "also run the peers installed in that Python (app/femcod_peers.py of "// &
            "the source tree: run from its root)"), &
         text_option("--fftw-wisdom", "FILE", "measured FFTW plans kept in FILE"), &
         choice_option("--nested", "on|off", "nested coarse-grid start (default on)"), &
         integer_option("--coarsest", "N", "coarsest grid (default 64)", lower=2), &
         real_option("--coarse-tol", "T", "tolerance of the coarse grids (default 1e-4)", lower=0.0_dp, closed="()"), &
         real_option("--single-until", "R", "float32 transforms above this residual (default 1e-5; 0: never)", &
            lower=0.0_dp), &
         integer_option("--direct", "N", "projection changes corrected directly (default 32; 0 with --split 0: two "// &
            "convolutions per iteration)", lower=0), &
         choice_option("--restart", "on|off", "restart the directions when pixels enter (default off)"), &
         integer_option("--split", "R", "window (pixels) of the kernel split that corrects projection changes "// &
            "beyond --direct (default 32; 0: a fresh convolution instead)", lower=0), &
         integer_option("--split-cell", "K", "lattice spacing (pixels) of the split's far part (default 8)", lower=1), &
         real_option("--split-budget", "B", "the split's near part at most B NP^2 multiply-adds (default 10)", &
            lower=0.0_dp), &
         real_option("--split-tolerance", "T", "split corrections while their error bound stays below T times the "// &
            "residual (default 1)", lower=0.0_dp), &
         choice_option("--precondition", "on|off", "the inverse-Love stencil (default on)"), &
         choice_option("--polak-ribiere", "on|off", "PR+ beta (default on; off: Fletcher-Reeves)"), &
         real_option("--powell", "NU", "Powell's restart when |z.g_old| >= NU z.g (default 0.2; 0: never)", &
            lower=0.0_dp), &
         real_option("--entry", "F", "entering pixels' force, F times the preconditioned step's for a lone pixel "// &
            "(default 0.25)", lower=0.0_dp, closed="()")]
   end function bench_cg_table

   !> The options of `femcod bench convolution`.
   function bench_convolution_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_list_option("--np", "N1,...", "grid sizes (default 512,1024,2048)", lower=2), &
         integer_option("--repeat", "N", "convolutions timed per size and precision (default 5)", lower=1)]
   end function bench_convolution_table

   !> The message of a failed parse, or of an argument the bench takes no positional for.
   !> Parse a bench command's arguments against its option table; false, with the
   !> message on standard error, when they do not fit it (or a positional is given).
   logical function bench_arguments(table, args, command, parsed) result(ok)
      type(option_spec), intent(in) :: table(:)
      type(string_type), intent(in) :: args(:)
      character(len=*), intent(in) :: command
      type(parsed_options), intent(out) :: parsed
      type(status_type) :: status
      call parse_options(table, args, parsed, status)
      if (status%code == 0 .and. size(parsed%positional) > 0) status%code = 2
      ok = status%code == 0
      if (.not. ok) write(error_unit, '(a)') command//": "//bad_arguments(status, parsed)//" ("// &
         trim(merge("femcod bench --help", "--help             ", command == "femcod bench"))//")"
   end function bench_arguments

   function bad_arguments(status, parsed) result(text)
      type(status_type), intent(in) :: status
      type(parsed_options), intent(in) :: parsed
      character(len=:), allocatable :: text
      if (allocated(status%message)) then
         text = status%message
      else
         text = "unknown argument "//parsed%positional(1)%s
      end if
   end function bad_arguments



   !> The benchmark surface of every table: self-affine, Hurst 0.8, rms 3 nm, 5 um square,
   !> NP x NP, E = 200 GPa, nu = 0.25, on the lower body against a rigid flat (seed 1).
   subroutine benchmark_surface(np, label, deck, status)
      integer, intent(in) :: np
      character(len=*), intent(in) :: label
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      spec%kind = "self-affine"
      spec%np = np
      spec%pixel = BENCH_LENGTH/np
      spec%hurst = 0.8_dp
      spec%rms = 3
      spec%seed = 1
      spec%shape_on = "lower"
      spec%rigid = "upper"
      spec%label = label
      spec%matrix_file = ""
      spec%maxcont = 1
      call build_problem(spec, deck, status)
   end subroutine benchmark_surface

   !> What the linear law of contact area needs: the composite modulus E* of the
   !> solver's model (elastic body on a rigid one) and the rms slope of the gaps; the
   !> mean pressure for a contact fraction f is f E* slope / 2 (kappa = 2).
   subroutine linear_law(deck, estar, slope, g0)
      type(contact_problem), intent(in) :: deck
      real(dp), intent(out) :: estar, slope
      real(dp), allocatable, intent(out) :: g0(:, :)
      integer :: np
      np = deck%np
      estar = 1/(1/(deck%young(1)/(1 - deck%poisson(1)**2)) + 1/(deck%young(2)/(1 - deck%poisson(2)**2)))
      g0 = transpose(reshape(initial_gaps(deck%lower, deck%upper), [np, np]))
      slope = sqrt((sum((g0(2:, :) - g0(:np - 1, :))**2) + sum((g0(:, 2:) - g0(:, :np - 1))**2)) &
         /(np*(np - 1.0_dp)))/deck%pixel
   end subroutine linear_law

   !> `femcod bench io`: the whole `femcod run` command, as a user runs it, against the
   !> solve inside it. For each NP: the deck written and read back (values per second),
   !> then `femcod run DECK --solver cg --loads L1,L5 -o PREFIX --force --quiet` (the
   !> loads of about 1 and 5 % contact) in a process of its own, its wall time against
   !> the solver's own (`wall_time_s` of PREFIX.summary.json): what is left is reading,
   !> set-up and every output. Then the pressure figure of the larger load made and
   !> written again here (time) and the largest figure on disk (bytes).
   subroutine bench_io(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer, allocatable :: sizes(:)
      character(len=:), allocatable :: dir, deck_path, prefix, command, text, svg
      type(contact_problem) :: deck, back
      type(status_type) :: status
      type(parsed_options) :: parsed
      type(h5_file) :: file
      real(dp), allocatable :: g0(:, :), map(:, :)
      real(dp) :: estar, slope, loads(2), t0, t1, t_write, t_read, t_run, t_solve, t_figure, outside, mpix, parts(5)
      integer :: n, np, ios
      integer(8) :: biggest
      sizes = [512, 1024, 2048]
      dir = "femcod-bench-io"
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod bench io [--np 512,1024,2048] [--dir DIR]", &
            "The whole command against the solve inside it, on the benchmark surface (self-affine, Hurst 0.8,", &
            "rms 3 nm, 5 um square, rigid flat, seed 1): deck written and read back, then femcod run --solver cg", &
            "at the loads of about 1 and 5 % contact in a process of its own, timed as a whole; its solver time", &
            "comes from PREFIX.summary.json. Then the pressure figure of the larger load, made and written again", &
            "here, and the largest figure's size. The files stay in DIR (default femcod-bench-io).", ""
         call print_lines(option_help(bench_io_table(), ""))
         write(output_unit, '(a)') "Columns: NP, deck write s (values/s), deck read s (values/s), run s, solver s,", &
            "outside the solver s (% of the solve, s per million pixels), and its parts from the run's own", &
            "timings_s in PREFIX.summary.json: reading the deck, the input digests, the maps, PREFIX.h5, the", &
            "text files and figures (the rest is starting the process and checks); figure s, largest figure KB."
         return
      end if
      if (.not. bench_arguments(bench_io_table(), args, "femcod bench io", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--np", sizes)
      call get_option(parsed, "--dir", dir)
      call execute_command_line("mkdir -p '"//dir//"'", exitstat=ios)
      write(output_unit, '(a)') "| NP | deck write s (values/s) | deck read s (values/s) | femcod run s | solver s "// &
         "| outside the solver s (% of solve, s/Mpixel) | read / digests / maps / h5 / text s | figure s "// &
         "| largest figure KB |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|"
      do n = 1, size(sizes)
         np = sizes(n)
         mpix = real(np, dp)**2/1.0e6_dp
         call benchmark_surface(np, "bench io", deck, status)
         call linear_law(deck, estar, slope, g0)
         loads = [1.0_dp, 5.0_dp]/100*estar*slope/2*BENCH_LENGTH**2
         deck_path = dir//"/io_"//int_str(np)//".deck"
         prefix = dir//"/io_"//int_str(np)
         call wall_clock(t0)
         call write_deck(deck_path, deck, status)
         call wall_clock(t1)
         t_write = t1 - t0
         call wall_clock(t0)
         call read_deck(deck_path, back, status)
         call wall_clock(t1)
         t_read = t1 - t0
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench io: "//status%message
            code = status%code
            return
         end if
         command = self_path()//" run '"//deck_path//"' --solver cg --loads "//real_str(loads(1), 17)//","// &
            real_str(loads(2), 17)//" -o '"//prefix//"' --force --quiet"
         call wall_clock(t0)
         call execute_command_line(command, exitstat=ios)
         call wall_clock(t1)
         t_run = t1 - t0
         if (ios /= 0) then
            write(error_unit, '(a)') "femcod bench io: "//command//" ended with exit code "//int_str(ios)
            code = 4
            return
         end if
         ! The solver's own time and the parts outside it, from the summary file.
         text = read_text_file(prefix//".summary.json")
         t_solve = json_value(text, '"wall_time_s"')
         outside = t_run - t_solve
         parts = [json_value(text, '"read_inputs"'), json_value(text, '"input_digests"'), &
            json_value(text, '"maps"'), json_value(text, '"write_hdf5"'), json_value(text, '"write_text_and_figures"')]
         ! The figure of the larger load, again, timed.
         call h5_open(prefix//".h5", file, status, 5)
         call h5_read(file, "/loads/002/pressure", map, status, 5)
         call h5_close(file, status)
         call wall_clock(t0)
         svg = svg_pressure_map("bench io", map, np*deck%pixel)
         call write_file(dir//"/figure.svg", svg, status)
         call wall_clock(t1)
         t_figure = t1 - t0
         biggest = largest_figure(prefix)
         write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(t_write, 2)//" ("//real_str(2*np**2/t_write, 2)// &
            ") | "//fixed_str(t_read, 2)//" ("//real_str(2*np**2/t_read, 2)//") | "//fixed_str(t_run, 2)//" | "// &
            fixed_str(t_solve, 2)//" | "//fixed_str(outside, 2)//" ("//fixed_str(100*outside/max(t_solve, 1.0e-9_dp), 0)// &
            " %, "//fixed_str(outside/mpix, 2)//") | "//fixed_str(parts(1), 2)//" / "//fixed_str(parts(2), 2)//" / "// &
            fixed_str(parts(3), 2)//" / "//fixed_str(parts(4), 2)//" / "//fixed_str(parts(5), 2)//" | "// &
            fixed_str(t_figure, 3)//" | "//fixed_str(biggest/1024.0_dp, 0)//" |"
         flush(output_unit)
      end do
   contains
      !> The largest of PREFIX's SVG figures, in bytes.
      integer(8) function largest_figure(prefix)
         character(len=*), intent(in) :: prefix
         character(len=*), parameter :: names(*) = [character(len=20) :: ".load_approach.svg", ".area_load.svg", &
            ".pressure_1.svg", ".pressure_2.svg"]
         integer(8) :: bytes
         integer :: k
         largest_figure = 0
         do k = 1, size(names)
            inquire(file=prefix//trim(names(k)), size=bytes)
            largest_figure = max(largest_figure, bytes)
         end do
      end function largest_figure
   end subroutine bench_io

   !> `femcod bench mpi`: the whole femcod-mpi command under mpirun, as a user runs it,
   !> against the whole serial `femcod run --solver cg`, on the benchmark surface (written
   !> once per NP as an HDF5 height file) at the load of about --contact % contact: wall
   !> time, the solve and its shares in transforms and communication (rank 0, from the
   !> run's PREFIX.summary.json), iterations, peak memory of the largest rank, and the
   !> approach's difference from the serial run's.
   subroutine bench_mpi(args, code)
      use omp_lib, only: omp_get_num_procs
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer, allocatable :: sizes(:), ranks(:)
      character(len=:), allocatable :: dir, heights, prefix, command, text, mpirun, program, common
      type(contact_problem) :: deck
      type(status_type) :: status
      type(parsed_options) :: parsed
      type(h5_file) :: file
      real(dp), allocatable :: g0(:, :)
      real(dp) :: estar, slope, load, t0, t1, tol, fraction, serial_approach, approach, t_solve, t_run, transform, &
         communication
      integer :: n, np, r, ios, threads, cores, per_node
      ! What the estimate needs, per NP: convolutions (iterations + fresh); of the 1-rank
      ! run its threads, transform, communication and solve seconds, peak MB and the peak
      ! MB of reading; of the largest run on more ranks its communication seconds and ranks.
      real(dp), allocatable :: measured(:, :)
      real(dp) :: network, latency_us
      sizes = [1024, 2048, 4096]
      ranks = [1, 2]
      fraction = 1
      tol = 1.0e-8_dp
      dir = "femcod-bench-mpi"
      mpirun = "mpirun --bind-to none"
      program = "femcod-mpi"
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod bench mpi [--np 1024,2048,4096] [--ranks 1,2] [--contact 1] [--tol 1e-8]", &
            "                        [--dir DIR] [--mpirun CMD] [--femcod-mpi PATH]", &
            "The whole femcod-mpi command (bash setup.sh --mpi) under CMD -np P for each P of --ranks, each", &
            "rank with cores/P OpenMP threads, against the whole serial femcod run --solver cg on all cores:", &
            "the benchmark surface (self-affine, Hurst 0.8, rms 3 nm, 5 um square, rigid flat, seed 1),", &
            "written once per NP as DIR/surface_NP.h5:/heights, at the load of about --contact % contact", &
            "(the linear law of femcod bench cg). As root, CMD gets --allow-run-as-root.", &
            "Then the estimate for 16384^2 to 65536^2 on 16 to 1024 ranks (one core each, --cores-per-node", &
            "per node, --network GB/s per node, --latency us per message), from this run's measured costs", &
            "(the method is printed).", ""
         call print_lines(option_help(bench_mpi_table(), ""))
         write(output_unit, '(a)') "Columns: NP, run, ranks x threads, whole command s, solve s, transforms % and", &
            "communication % of the solve (rank 0: the 1-D FFTs; FFTW-MPI's transposes, the sums and halos,", &
            "waiting included), iterations (+ coarse, fresh convolutions), peak MB of the largest rank,", &
            "contact %, approach's difference from the serial run's (relative)."
         return
      end if
      if (.not. bench_arguments(bench_mpi_table(), args, "femcod bench mpi", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--np", sizes)
      call get_option(parsed, "--ranks", ranks)
      call get_option(parsed, "--contact", fraction)
      call get_option(parsed, "--tol", tol)
      call get_option(parsed, "--dir", dir)
      call get_option(parsed, "--mpirun", mpirun)
      call get_option(parsed, "--femcod-mpi", program)
      per_node = 32
      network = 12.5_dp
      latency_us = 2
      call get_option(parsed, "--cores-per-node", per_node)
      call get_option(parsed, "--network", network)
      call get_option(parsed, "--latency", latency_us)
      allocate(measured(9, size(sizes)))
      measured = 0
      if (is_root()) mpirun = mpirun//" --allow-run-as-root"
      cores = omp_get_num_procs()
      call execute_command_line("mkdir -p '"//dir//"'", exitstat=ios)
      write(output_unit, '(a)') "| NP | run | ranks x threads | whole command s | solve s | transforms % | "// &
         "communication % | iterations | peak MB (largest rank) | contact % | approach vs serial |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|---|---|"
      do n = 1, size(sizes)
         np = sizes(n)
         call benchmark_surface(np, "bench mpi", deck, status)
         call linear_law(deck, estar, slope, g0)
         deallocate(g0)
         load = fraction/100*estar*slope/2*BENCH_LENGTH**2
         heights = dir//"/surface_"//int_str(np)//".h5"
         call h5_create(heights, file, status)
         call h5_write(file, "/heights", deck%lower, "nm", status)
         call h5_close(file, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench mpi: "//status%message
            code = status%code
            return
         end if
         common = " --lower '"//heights//":/heights' --pixel "//real_str(deck%pixel, 17)//" --loads "// &
            real_str(load, 17)//" --tol "//real_str(tol, 3)//" --force --quiet"
         deallocate(deck%lower, deck%upper)
         ! The serial command on all cores.
         prefix = dir//"/serial_"//int_str(np)
         command = "OMP_NUM_THREADS="//int_str(cores)//" "//self_path()//" run --solver cg"//common//" -o '"//prefix//"'"
         call timed(command, t_run, ios)
         if (ios /= 0) then
            write(output_unit, '(a)') "| "//int_str(np)//" | femcod run | 1 x "//int_str(cores)//" | | | | | | | | "// &
               "exit code "//int_str(ios)//" |"
            cycle
         end if
         text = read_text_file(prefix//".summary.json")
         serial_approach = json_value(text, '"approach_nm"')
         write(output_unit, '(a)') "| "//int_str(np)//" | femcod run | 1 x "//int_str(cores)//" | "// &
            fixed_str(t_run, 2)//" | "//fixed_str(json_value(text, '"wall_time_s"'), 2)//" | | | "// &
            int_str(nint(json_value(text, '"iterations"')))//" | | "// &
            fixed_str(100*json_value(text, '"area_fraction"'), 2)//" | (reference) |"
         flush(output_unit)
         do r = 1, size(ranks)
            threads = max(1, cores/ranks(r))
            prefix = dir//"/mpi_"//int_str(np)//"_"//int_str(ranks(r))
            command = "OMP_NUM_THREADS="//int_str(threads)//" "//mpirun//" -np "//int_str(ranks(r))//" "//program// &
               common//" -o '"//prefix//"'"
            call timed(command, t_run, ios)
            if (ios /= 0) then
               write(output_unit, '(a)') "| "//int_str(np)//" | femcod-mpi | "//int_str(ranks(r))//" x "// &
                  int_str(threads)//" | | | | | | | | exit code "//int_str(ios)//" |"
               cycle
            end if
            text = read_text_file(prefix//".summary.json")
            t_solve = json_value(text, '"solve_time_s"')
            measured(1, n) = json_value(text, '"iterations"') + json_value(text, '"convolutions"')
            if (ranks(r) == 1) measured([2, 3, 4, 5, 6, 9], n) = [real(threads, dp), json_value(text, '"transform_s"'), &
               json_value(text, '"communication_s"'), t_solve, json_list_max(text, '"peak_memory_MB_per_rank"'), &
               json_value(text, '"read_peak_memory_MB"')]
            if (ranks(r) > 1 .and. ranks(r) >= measured(8, n)) measured(7:8, n) = &
               [json_value(text, '"communication_s"'), real(ranks(r), dp)]
            approach = json_value(text, '"approach_nm"')
            transform = json_value(text, '"transform_s"')
            communication = json_value(text, '"communication_s"')
            write(output_unit, '(a)') "| "//int_str(np)//" | femcod-mpi | "//int_str(ranks(r))//" x "// &
               int_str(threads)//" | "//fixed_str(t_run, 2)//" | "//fixed_str(t_solve, 2)//" | "// &
               int_str(nint(100*transform/max(t_solve, 1.0e-9_dp)))//" | "// &
               int_str(nint(100*communication/max(t_solve, 1.0e-9_dp)))//" | "// &
               int_str(nint(json_value(text, '"iterations"')))//" (+"// &
               int_str(nint(json_value(text, '"coarse_iterations"')))//" coarse, "// &
               int_str(nint(json_value(text, '"convolutions"')))//" fresh) | "// &
               int_str(nint(json_list_max(text, '"peak_memory_MB_per_rank"')))//" | "// &
               fixed_str(100*json_value(text, '"area_fraction"'), 2)//" | "// &
               real_str(abs(approach - serial_approach)/abs(serial_approach), 2)//" |"
            flush(output_unit)
         end do
      end do
      call print_mpi_estimate(sizes, measured, per_node, network, latency_us)
   contains
      subroutine timed(command, seconds, status_code)
         character(len=*), intent(in) :: command
         real(dp), intent(out) :: seconds
         integer, intent(out) :: status_code
         call wall_clock(t0)
         call execute_command_line(command, exitstat=status_code)
         call wall_clock(t1)
         seconds = t1 - t0
      end subroutine timed

      logical function is_root()
         integer :: stat
         call execute_command_line('test "$(id -u)" -eq 0', exitstat=stat)
         is_root = stat == 0
      end function is_root
   end subroutine bench_mpi

   !> The options of `femcod bench mpi`.
   function bench_mpi_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_list_option("--np", "N1,...", "grid sizes (default 1024,2048,4096)", lower=4), &
         integer_list_option("--ranks", "P1,...", "MPI ranks (default 1,2)", lower=1), &
         real_option("--contact", "F", "contact fraction in percent (default 1)", lower=0.0_dp), &
         real_option("--tol", "T", "the cg stopping tolerance (default 1e-8)", lower=0.0_dp), &
         text_option("--dir", "DIR", "where the height files and results go (default femcod-bench-mpi)"), &
         text_option("--mpirun", "CMD", "the MPI launcher and its options (default 'mpirun --bind-to none')"), &
         text_option("--femcod-mpi", "PATH", "the femcod-mpi program (default: femcod-mpi on PATH)"), &
         integer_option("--cores-per-node", "C", "the estimate's cores per node (default 32)", lower=1), &
         real_option("--network", "B", "the estimate's network bandwidth per node in GB/s (default 12.5)", &
            lower=0.0_dp, closed="()"), &
         real_option("--latency", "US", "the estimate's time per message in microseconds (default 2)", lower=0.0_dp)]
   end function bench_mpi_table

   !> The estimate of femcod-mpi at 16384^2, 32768^2 and 65536^2 on 16 to 1024 ranks (one
   !> core each, `per_node` per node), from the measured costs of the largest NP that ran
   !> on 1 rank (measured(:, n), bench_mpi): convolutions grow as NP^beta (beta fitted to
   !> every NP measured, least squares in logs); each convolution costs k NP^2 log2(2 NP)
   !> core-seconds in the transforms and r NP^2 in the rest (both measured on 1 rank,
   !> times its threads), divided over the ranks, plus moving its two transposes (32 NP^2
   !> bytes): over the network at `network` GB/s per node, a share (N - 1)/N^2 per node of
   !> N, or within one node at the rate measured here on more ranks; plus 4 P messages of
   !> `latency_us` each. Memory per rank: the 1-rank peak per pixel over P; rank 0 reads the input
   !> besides (its peak before the solve allocates, per pixel, measured).
   subroutine print_mpi_estimate(sizes, measured, per_node, network, latency_us)
      integer, intent(in) :: sizes(:)
      real(dp), intent(in) :: measured(:, :)
      integer, intent(in) :: per_node
      !> GB/s per node between nodes, and us per message.
      real(dp), intent(in) :: network, latency_us
      integer, parameter :: targets(3) = [16384, 32768, 65536], rank_counts(4) = [16, 64, 256, 1024]
      real(dp) :: beta, sx, sy, sxx, sxy, k, r, bytes_px, read_px, local_rate, np0, conv0, conv, compute, moving, &
         latency, x, y
      integer :: n, base, t, p, nodes, count
      base = 0
      do n = 1, size(sizes)
         if (measured(2, n) > 0 .and. measured(1, n) > 0) then
            if (base == 0) then
               base = n
            else if (sizes(n) > sizes(base)) then
               base = n
            end if
         end if
      end do
      if (base == 0) then
         write(output_unit, '(a)') "", "No estimate: it needs a run on 1 rank (--ranks 1,...)."
         return
      end if
      ! beta from every NP with a convolution count.
      count = 0
      sx = 0
      sy = 0
      sxx = 0
      sxy = 0
      do n = 1, size(sizes)
         if (.not. measured(1, n) > 0) cycle
         count = count + 1
         x = log(real(sizes(n), dp))
         y = log(measured(1, n))
         sx = sx + x
         sy = sy + y
         sxx = sxx + x*x
         sxy = sxy + x*y
      end do
      beta = 0
      if (count >= 2) beta = (count*sxy - sx*sy)/(count*sxx - sx*sx)
      np0 = sizes(base)
      conv0 = measured(1, base)
      k = measured(3, base)*measured(2, base)/(conv0*np0**2*log(2*np0)/log(2.0_dp))
      r = max(0.0_dp, measured(5, base) - measured(3, base) - measured(4, base))*measured(2, base)/(conv0*np0**2)
      bytes_px = measured(6, base)*1048576/np0**2
      read_px = measured(9, base)*1048576/np0**2
      local_rate = 0
      if (measured(7, base) > 0) local_rate = 32*np0**2/(measured(7, base)/conv0)
      write(output_unit, '(a)') "", "Estimate (from NP = "//int_str(sizes(base))//" on 1 rank x "// &
         int_str(nint(measured(2, base)))//" threads: "//real_str(k, 3)//" core-s per pixel and log2(2 NP) in the "// &
         "transforms and "//real_str(r, 3)//" core-s per pixel in the rest, per convolution; "// &
         int_str(nint(bytes_px))//" bytes per pixel, "//int_str(nint(read_px))//" for reading on rank 0; "// &
         "convolutions ~ NP^"//fixed_str(beta, 2)//" from "// &
         int_str(count)//" sizes; within a node the transposes move "//real_str(local_rate/1.0e9_dp, 2)// &
         " GB/s on "//int_str(nint(measured(8, base)))//" ranks (measured; P ranks in one node taken to move P/"// &
         int_str(nint(measured(8, base)))//" times as much), between nodes "// &
         fixed_str(network, 1)//" GB/s per node and "//fixed_str(latency_us, 1)//" us per message, "// &
         int_str(per_node)//" ranks per node):"
      ! The model's own check: twice the base NP on this machine's cores (1 rank with the
      ! measured threads, and the measured larger rank count sharing them).
      x = 2*np0
      conv = conv0*2**beta
      compute = (k*x**2*log(2*x)/log(2.0_dp) + r*x**2)/measured(2, base)
      write(output_unit, '(a)') "", "Check on this machine, NP = "//int_str(nint(x))//": "//int_str(nint(conv))// &
         " convolutions, "//int_str(nint(conv*(compute + measured(4, base)/conv0*4)))//" s on 1 rank x "// &
         int_str(nint(measured(2, base)))//" threads"
      if (local_rate > 0) write(output_unit, '(a)') "  and "//int_str(nint(conv*(compute + 32*x**2/local_rate)))// &
         " s on "//int_str(nint(measured(8, base)))//" ranks sharing the same cores (run --np "//int_str(nint(x))// &
         " to compare)."
      write(output_unit, '(a)') "", "| NP | ranks | nodes | memory per rank GB (rank 0 reads GB) | convolutions | "// &
         "compute s / convolution | transposes s / convolution | solve estimate s |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|"
      do t = 1, size(targets)
         do p = 1, size(rank_counts)
            nodes = max(1, (rank_counts(p) + per_node - 1)/per_node)
            x = real(targets(t), dp)
            conv = conv0*(x/np0)**beta
            compute = (k*x**2*log(2*x)/log(2.0_dp) + r*x**2)/rank_counts(p)
            if (nodes > 1) then
               moving = 32*x**2*(nodes - 1)/(real(nodes, dp)**2*network*1.0e9_dp)
            else if (local_rate > 0) then
               moving = 32*x**2/(local_rate*rank_counts(p)/measured(8, base))
            else
               moving = 0
            end if
            latency = 4*rank_counts(p)*latency_us*1.0e-6_dp
            write(output_unit, '(a)') "| "//int_str(targets(t))//" | "//int_str(rank_counts(p))//" | "// &
               int_str(nodes)//" | "//fixed_str(bytes_px*x**2/rank_counts(p)/1.0e9_dp, 2)//" ("// &
               fixed_str(read_px*x**2/1.0e9_dp, 1)//") | "//int_str(nint(conv))//" | "//fixed_str(compute, 3)//" | "// &
               fixed_str(moving + latency, 3)//" | "//int_str(nint(conv*(compute + moving + latency)))//" |"
         end do
      end do
   end subroutine print_mpi_estimate

   !> The largest number of the list after `"key": [` in the JSON text (0 when absent).
   real(dp) function json_list_max(t, key)
      character(len=*), intent(in) :: t, key
      real(dp), allocatable :: values(:)
      integer :: at, ends, ios, n
      json_list_max = 0
      at = index(t, key//": [")
      if (at == 0) return
      at = at + len(key) + 3
      ends = index(t(at:), "]")
      if (ends <= 1) return
      n = 1 + count([(t(at + ios - 1:at + ios - 1) == ",", ios = 1, ends - 1)])
      allocate(values(n))
      read(t(at:at + ends - 2), *, iostat=ios) values
      if (ios == 0) json_list_max = maxval(values)
   end function json_list_max

   !> This program's path (argument 0).
   function self_path() result(path)
      character(len=:), allocatable :: path
      integer :: length
      call get_command_argument(0, length=length)
      allocate(character(len=length) :: path)
      call get_command_argument(0, path)
   end function self_path

   !> The peers' script: app/femcod_peers.py of the source tree (run from its root), or
   !> the copy `setup.sh` installs beside femcod (PREFIX/share/femcod/femcod_peers.py for
   !> PREFIX/bin/femcod); "" when neither exists.
   function peers_script() result(path)
      character(len=:), allocatable :: path, exe
      integer :: slash
      path = "app/femcod_peers.py"
      if (path_exists(path)) return
      exe = canonical_path("/proc/self/exe")
      slash = index(exe, "/", back=.true.)
      path = ""
      if (slash > 1) then
         path = exe(1:slash - 1)//"/../share/femcod/femcod_peers.py"
         if (.not. path_exists(path)) path = ""
      end if
   end function peers_script

   !> The thesis deck of bench frontier: --deck FILE read, or by default
   !> input/sphere_d1.deck built in memory from its verification spec (the bench runs
   !> from any directory).
   subroutine frontier_deck(path, given, deck, status)
      character(len=*), intent(in) :: path
      logical, intent(in) :: given
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(scene_spec) :: builtin
      if (given) then
         call read_deck(path, deck, status)
      else
         call verification_spec("sphere_d1", builtin, status)
         if (status%code == 0) call build_problem(builtin, deck, status)
      end if
   end subroutine frontier_deck

   !> With --peers PYTHON, the peers' script must be found before any work (exit 2).
   subroutine require_peers(python, command, code)
      character(len=*), intent(in) :: python, command
      integer, intent(inout) :: code
      if (len(python) == 0 .or. code /= 0) return
      if (len(peers_script()) > 0) return
      write(error_unit, '(a)') "femcod bench "//command//": --peers needs femcod_peers.py: app/femcod_peers.py "// &
         "of the source tree (run from its root) or the copy setup.sh installs in PREFIX/share/femcod; found neither"
      code = 2
   end subroutine require_peers

   !> The number after `"key": ` in the JSON text (its first occurrence; 0 when absent).
   real(dp) function json_value(t, key)
      character(len=*), intent(in) :: t, key
      integer :: at, ends, ios2
      json_value = 0
      at = index(t, key//": ")
      if (at == 0) return
      at = at + len(key) + 2
      ends = scan(t(at:), ",}"//new_line("a"))
      if (ends == 0) return
      read(t(at:at + ends - 2), *, iostat=ios2) json_value
      if (ios2 /= 0) json_value = 0
   end function json_value

   function read_text_file(path) result(t)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: t
      integer :: unit, size_bytes, ios2
      open(newunit=unit, file=path, access="stream", form="unformatted", action="read", status="old", iostat=ios2)
      if (ios2 /= 0) then
         t = ""
         return
      end if
      inquire(unit=unit, size=size_bytes)
      allocate(character(len=size_bytes) :: t)
      read(unit, iostat=ios2) t
      close(unit)
   end function read_text_file

   !> The options of `femcod bench io`.
   function bench_io_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_list_option("--np", "N1,...", "grid sizes (default 512,1024,2048)", lower=2), &
         text_option("--dir", "DIR", "where the decks and results go (default femcod-bench-io)")]
   end function bench_io_table

   !> `femcod bench periodic`: the periodic boundary against Westergaard's sinusoid at 64
   !> to 1024 pixels per period (the discretisation error and its order), and the cost of
   !> the periodic cg solver against the free one on the benchmark surface.
   subroutine bench_periodic(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      real(dp), parameter :: pi = acos(-1.0_dp), widths(3) = [1.0_dp/6, 1.0_dp/4, 1.0_dp/3]
      character(len=*), parameter :: boundaries(2) = [character(len=8) :: "free", "periodic"]
      integer, allocatable :: sizes(:), rough_sizes(:)
      real(dp), allocatable :: fractions(:), z(:, :), g0(:, :), s(:, :), previous(:)
      type(contact_problem) :: deck
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: res
      type(parsed_options) :: parsed
      real(dp) :: estar, pstar, lambda, ratio, closed, slope, load, peak
      real(dp), allocatable :: approach_error(:)
      real(dp) :: tol, pressure, fraction
      character(len=:), allocatable :: python, path
      character(len=512) :: line
      character(len=64) :: words(8)
      character(len=*), parameter :: peers(2) = [character(len=25) :: "tamaas", "contactmechanics-periodic"]
      integer :: n, np, j, k, b, width, i, ios
      sizes = [64, 128, 256, 512, 1024]
      rough_sizes = [512, 1024]
      fractions = [1.0_dp, 10.0_dp, 30.0_dp]
      tol = 1.0e-8_dp
      python = ""
      if (help_requested(args)) then
         write(output_unit, '(a)') &
            "usage: femcod bench periodic [--np 64,128,256,512,1024] [--rough-np 512,1024] [--contact 1,10,30]", &
            "       [--tol 1e-8] [--peers PYTHON]", &
            "1. Westergaard's sinusoid h = cos(2 pi x / lambda) nm, lambda = NP pixels of 1 nm, E = 200 GPa,", &
            "   nu = 0.25, on a rigid flat, --boundary periodic, cg to 1e-10: at the mean pressures of the", &
            "   contact half-widths a/lambda = 1/6, 1/4, 1/3 (p = p* sin^2(pi a/lambda), p* = pi E* h0/lambda),", &
            "   the contact width on a row against 2a (pixels), the approach against the closed form", &
            "   A/h0 = (p/p*)(1 - ln(p/p*)) with its observed order, and the discrete full-contact pressure", &
            "   against p* (from the kernel's spectrum: p_full/p* = NP/S(1/NP, 0)).", &
            "2. The benchmark surface (self-affine, periodic by construction) at --contact fractions,", &
            "   cg with each boundary: solve time, iterations, contact %, mean gap, peak RSS; with --peers,", &
            "   tamaas (PolonskyKeerRey) and ContactMechanics (PeriodicFFTElasticHalfSpace) on the same", &
            "   gaps, pressure and tolerance, from that Python (app/femcod_peers.py; never a dependency).", ""
         call print_lines(option_help(bench_periodic_table(), ""))
         write(output_unit, '(a)') "Run it with the release build."
         return
      end if
      if (.not. bench_arguments(bench_periodic_table(), args, "femcod bench periodic", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--np", sizes)
      call get_option(parsed, "--rough-np", rough_sizes)
      call get_option(parsed, "--contact", fractions)
      call get_option(parsed, "--tol", tol)
      call get_option(parsed, "--peers", python)
      call require_peers(python, "periodic", code)
      if (code /= 0) return
      options%solver = "cg"
      options%boundary = "periodic"
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      estar = 200/(1 - 0.25_dp**2)
      write(output_unit, '(a)') "| pixels per period | a/lambda | width (pixels) | 2a (pixels) | approach (nm) | "// &
         "closed form (nm) | relative error | order | p_full/p* - 1 | wall (s) |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|---|"
      allocate(previous(size(widths)), approach_error(size(widths)))
      previous = 0
      do n = 1, size(sizes)
         np = sizes(n)
         allocate(z(np, np))
         do j = 1, np
            z(:, j) = cos(2*pi*(j - 1)/np)
         end do
         deck%label = "bench periodic"
         deck%np = np
         deck%pixel = 1
         deck%maxcont = np*np
         deck%young = [200.0_dp, 200*RIGID_FACTOR, 200*RIGID_FACTOR]
         deck%poisson = 0.25_dp
         deck%lower = z
         deck%upper = 0*z
         lambda = np*deck%pixel
         pstar = pi*estar/lambda
         options%loads = [(pstar*sin(pi*widths(k))**2*lambda**2, k = 1, size(widths))]
         call solve_contact(deck, options, res, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench periodic: "//status%message
            code = status%code
            return
         end if
         allocate(s(0:np/2, 0:np/2))
         s(:, :) = periodic_love_spectrum(np)
         do k = 1, size(widths)
            width = count(res%states(k)%i == 1)
            ratio = sin(pi*widths(k))**2
            closed = ratio*(1 - log(ratio))
            approach_error(k) = abs(res%states(k)%approach/closed - 1)
            write(output_unit, '(a)') "| "//int_str(np)//" | 1/"//int_str(nint(1/widths(k)))//" | "//int_str(width)// &
               " | "//fixed_str(2*widths(k)*np, 2)//" | "//real_str(res%states(k)%approach, 8)//" | "// &
               real_str(closed, 8)//" | "//real_str(approach_error(k), 2)//" | "// &
               trim(merge(fixed_str(log(previous(k)/approach_error(k))/log(2.0_dp), 2), "-                 ", &
               previous(k) > 0 .and. approach_error(k) > 0))//" | "//real_str(np/s(1, 0) - 1, 3)//" | "// &
               fixed_str(res%wall_seconds, 2)//" |"
         end do
         previous = approach_error
         flush(output_unit)
         deallocate(z, s)
      end do
      write(output_unit, '(a)') "", "| NP | target % | solver | boundary | wall (s) | iterations | contact % | "// &
         "mean gap (nm) | peak RSS (MB) |", "|---|---|---|---|---|---|---|---|---|"
      do n = 1, size(rough_sizes)
         np = rough_sizes(n)
         call benchmark_surface(np, "bench periodic", deck, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench periodic: "//status%message
            code = status%code
            return
         end if
         call linear_law(deck, estar, slope, g0)
         path = "femcod-bench-gaps.f64"
         if (len(python) > 0) call write_peer_gaps(path, g0)
         ! The peers read the file: the bench's own copy of the gaps is not the solver's.
         deallocate(g0)
         do k = 1, size(fractions)
            pressure = fractions(k)/100*estar*slope/2
            load = pressure*BENCH_LENGTH**2
            do b = 1, size(boundaries)
               options%boundary = boundaries(b)
               options%loads = [load]
               options%cg = cg_settings()
               options%cg%tol = tol
               options%cg%max_iterations = 5000
               call reset_peak()
               call solve_contact(deck, options, res, status)
               peak = peak_mb()
               if (status%code /= 0) then
                  write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(fractions(k), 1)//" | femcod cg | "// &
                     trim(boundaries(b))//" | "//status%message//" | | | | |"
                  status = status_type()
                  cycle
               end if
               write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(fractions(k), 1)//" | femcod cg | "// &
                  trim(boundaries(b))//" | "//fixed_str(res%wall_seconds, 2)//" | "// &
                  int_str(res%states(1)%iterations)//" (+"//int_str(res%states(1)%coarse_iterations)//" coarse) | "// &
                  fixed_str(100*res%states(1)%contacts/real(np, dp)**2, 3)//" | "// &
                  real_str(sum(res%states(1)%gap)/real(np, dp)**2, 7)//" | "//fixed_str(peak, 0)//" |"
               flush(output_unit)
            end do
            if (len(python) == 0) cycle
            do i = 1, size(peers)
               line = peer_line(python, trim(peers(i)), path, np, deck%pixel, estar, pressure, tol)
               words = "-"
               read(line, *, iostat=ios) words
               read(words(5), *, iostat=ios) fraction
               if (ios == 0) words(5) = fixed_str(100*fraction, 3)
               write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(fractions(k), 1)//" | "// &
                  trim(words(1))//" | periodic | "//trim(words(2))//" | "//trim(words(3))//" | "//trim(words(5))// &
                  " | "//trim(words(8))//" | "//trim(words(6))//" |"
               flush(output_unit)
            end do
         end do
         if (len(python) > 0) call remove_file_quietly(path)
      end do
   end subroutine bench_periodic

   function bench_periodic_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_list_option("--np", "N1,...", "pixels per period of the sinusoid (default "// &
         "64,128,256,512,1024)", lower=8), &
         integer_list_option("--rough-np", "N1,...", "sizes of the benchmark surface (default 512,1024)", lower=8), &
         real_list_option("--contact", "F1,...", "contact fractions in percent (default 1,10,30)", lower=0.0_dp), &
         real_option("--tol", "T", "tolerance of the rough-surface solves, femcod's and the peers' (default 1e-8)", &
            lower=0.0_dp, closed="()"), &
         text_option("--peers", "PYTHON", "a Python with tamaas and ContactMechanics installed")]
   end function bench_periodic_table

   !> `femcod bench frontier`: every way femcod answers "approach and contact area at
   !> load F" on the benchmark surface, as wall time against the relative error of each
   !> against the event-exact answer at that load (issue 21's frontier, first part).
   subroutine bench_frontier(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer :: np, k, f, m, factor, method
      real(dp), allocatable :: fractions(:), g0(:, :)
      character(len=:), allocatable :: svg_path, deck_path, case_label
      type(contact_problem) :: thesis
      real(dp) :: deck_load
      type(contact_problem) :: deck, coarse
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: res
      type(parsed_options) :: parsed
      type(svg_series), allocatable :: series(:)
      real(dp), allocatable :: times(:), errors(:)
      real(dp) :: estar, slope, load, a_ref, c_ref, t0, t1, approach, area
      real(dp), parameter :: tols(5) = [1.0e-2_dp, 1.0e-4_dp, 1.0e-6_dp, 1.0e-8_dp, 1.0e-10_dp]
      real(dp), parameter :: radii(4) = [28.0_dp, 64.0_dp, 128.0_dp, 283.0_dp]
      character(len=*), parameter :: methods(2) = [character(len=9) :: "average", "subsample"]
      np = 256
      fractions = [1.0_dp, 5.0_dp]
      svg_path = ""
      deck_path = "input/sphere_d1.deck"
      deck_load = 1000
      if (help_requested(args)) then
         write(output_unit, '(a)') &
            "usage: femcod bench frontier [--np 256] [--contact 1,5] [--svg FILE]", &
            "On the benchmark surface (self-affine, Hurst 0.8, rms 3 nm, 5 um, NP x NP) at the mean pressures", &
            "of about the given contact fractions: the event-exact answer (approach A and contact area C at", &
            "load F), then every cheaper way to it, each a row of wall time (the solve with its set-up, no", &
            "file I/O) and relative errors |A - A_exact|/A_exact and |C - C_exact|/C_exact: cg at --tol", &
            "1e-2 to 1e-10 with and without float32 transforms and the nested start; cg with the Love", &
            "kernel truncated at 28, 64, 128, 283 pixels (--kernel-radius); the event path on the", &
            "image down-sampled by 2, 4, 8 (2 x 2 averages and odd/odd subsampling); the uncoupled voxel", &
            "model (its approach at F, exact between sorted gaps); McCool's Greenwood-Williamson estimate", &
            "(area only). Then a thesis deck (--deck, at --deck-load) the same ways and by the Appendix B", &
            "program (--solver legacy).", &
            "--svg FILE: log time against log area error, one marker per method and the Pareto front.", ""
         call print_lines(option_help(bench_frontier_table(), ""))
         write(output_unit, '(a)') "Run it with the release build."
         return
      end if
      if (.not. bench_arguments(bench_frontier_table(), args, "femcod bench frontier", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--np", np)
      call get_option(parsed, "--contact", fractions)
      call get_option(parsed, "--svg", svg_path)
      call get_option(parsed, "--deck", deck_path)
      if (option_given(parsed, "--no-deck")) deck_path = ""
      call get_option(parsed, "--deck-load", deck_load)
      ! The thesis deck first, so that a bad --deck fails before the table's work.
      if (len(deck_path) > 0) then
         call frontier_deck(deck_path, option_given(parsed, "--deck"), thesis, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench frontier: "//status%message
            code = status%code
            return
         end if
      end if
      call benchmark_surface(np, "bench frontier", deck, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod bench frontier: "//status%message
         code = status%code
         return
      end if
      deck%maxcont = np*np
      call linear_law(deck, estar, slope, g0)
      write(output_unit, '(a)') "| case | method | wall (s) | approach error | area error | note |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|"
      allocate(series(0))
      do f = 1, size(fractions)
         load = fractions(f)/100*estar*slope/2*BENCH_LENGTH**2
         case_label = fixed_str(fractions(f), 1)//" %"
         call frontier_case(load, .false.)
         if (status%code /= 0) return
      end do
      ! One thesis deck, with the Appendix B program among the methods.
      if (len(deck_path) > 0) then
         deck = thesis
         np = deck%np
         g0 = transpose(reshape(initial_gaps(deck%lower, deck%upper), [np, np]))
         case_label = file_part(deck_path)
         call frontier_case(deck_load, .true.)
         if (status%code /= 0) return
      end if
      if (len(svg_path) > 0) then
         call write_file(svg_path, svg_multi_plot("speed against error: approach and area at load F (NP = "// &
            int_str(np)//")", "wall time (s)", "relative error of the contact area", series, .true., .true.), status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench frontier: "//status%message
            code = status%code
         end if
      end if
   contains
      !> Every method at load F on `deck` (np, g0 its grid and gaps), rows labelled
      !> case_label; with `legacy`, the Appendix B program as well.
      subroutine frontier_case(load, legacy)
         real(dp), intent(in) :: load
         logical, intent(in) :: legacy
         allocate(times(0), errors(0))
            ! The reference: the event-exact state at F.
            options = contact_options()
            options%loads = [load]
            call timed_solve(deck, options, res, t1)
            if (status%code /= 0) return
            a_ref = res%states(1)%approach
            c_ref = res%states(1)%contacts*deck%pixel**2
            call frontier_row("event-exact (reference)", t1, 0.0_dp, 0.0_dp, "F = "//real_str(load, 6)//" nN, "// &
               int_str(res%states(1)%contacts)//" contacts")
            ! cg at each tolerance, with and without float32 and the nested start.
            do m = 1, 4
               do k = 1, size(tols)
                  options = contact_options()
                  options%solver = "cg"
                  options%loads = [load]
                  options%cg = cg_settings()
                  options%cg%tol = tols(k)
                  options%cg%max_iterations = 5000
                  if (m == 2 .or. m == 4) options%cg%single_until = 0
                  if (m >= 3) options%cg%nested = .false.
                  call timed_solve(deck, options, res, t1)
                  if (status%code /= 0) then
                     call frontier_row("cg tol "//real_str(tols(k), 1), -1.0_dp, -1.0_dp, -1.0_dp, status%message)
                     status = status_type()
                     cycle
                  end if
                  call frontier_row("cg tol "//real_str(tols(k), 1)//trim(merge(", no float32", "            ", &
                     m == 2 .or. m == 4))//trim(merge(", no nested start", "                 ", m >= 3)), t1, &
                     rel(res%states(1)%approach, a_ref), rel(res%states(1)%contacts*deck%pixel**2, c_ref), &
                     int_str(res%states(1)%iterations)//" iterations, approach bound "// &
                     real_str(res%states(1)%approach_bound/abs(a_ref), 2))
               end do
            end do
            ! The Love kernel truncated (the thesis' 28 and 283 pixels, section 5.2.2 iii).
            do k = 1, size(radii)
               options = contact_options()
               options%solver = "cg"
               options%loads = [load]
               options%cg = cg_settings()
               options%cg%max_iterations = 5000
               options%cg%kernel_radius = radii(k)
               call timed_solve(deck, options, res, t1)
               if (status%code /= 0) then
                  call frontier_row("cg, kernel truncated at "//int_str(nint(radii(k)))//" pixels", -1.0_dp, -1.0_dp, &
                     -1.0_dp, status%message)
                  status = status_type()
                  cycle
               end if
               call frontier_row("cg, kernel truncated at "//int_str(nint(radii(k)))//" pixels", t1, &
                  rel(res%states(1)%approach, a_ref), rel(res%states(1)%contacts*deck%pixel**2, c_ref), &
                  int_str(res%states(1)%iterations)//" iterations, tol 1e-8")
            end do
            ! The image down-sampled, the event path at the same load.
            do method = 1, size(methods)
               factor = 2
               do while (factor <= 8 .and. np/factor >= 8 .and. mod(np, factor) == 0)
                  call wall_clock(t0)
                  call level_deck(deck, np/factor, trim(methods(method)), coarse, status)
                  options = contact_options()
                  options%loads = [load]
                  if (status%code == 0) call solve_contact(coarse, options, res, status)
                  call wall_clock(t1)
                  if (status%code /= 0 .or. .not. res%states(1)%reached) then
                     call frontier_row("down-sampled 1/"//int_str(factor)//", "//trim(methods(method)), -1.0_dp, &
                        -1.0_dp, -1.0_dp, "not reached: "//status%message)
                     status = status_type()
                  else
                     call frontier_row("down-sampled 1/"//int_str(factor)//", "//trim(methods(method)), t1 - t0, &
                        rel(res%states(1)%approach, a_ref), rel(res%states(1)%contacts*coarse%pixel**2, c_ref), &
                        int_str(np/factor)//"^2 pixels")
                  end if
                  factor = 2*factor
               end do
            end do
            ! The uncoupled voxels: the approach where their load is F, by bisection.
            call wall_clock(t0)
            call uncoupled_at(load, approach, area)
            call wall_clock(t1)
            call frontier_row("uncoupled voxels", t1 - t0, rel(approach, a_ref), rel(area, c_ref), &
               "single-pixel compliance, no coupling")
            ! McCool's Greenwood-Williamson model: the area at the nominal pressure.
            call wall_clock(t0)
            call mccool_at(load, area)
            call wall_clock(t1)
            call frontier_row("McCool (Greenwood-Williamson)", t1 - t0, -1.0_dp, rel(area, c_ref), "area only")
            if (legacy) then
               options = contact_options()
               options%solver = "legacy"
               options%loads = [load]
               call timed_solve(deck, options, res, t1)
               if (status%code /= 0) then
                  call frontier_row("legacy (Appendix B)", -1.0_dp, -1.0_dp, -1.0_dp, status%message)
                  status = status_type()
               else
                  call frontier_row("legacy (Appendix B)", t1, rel(res%states(1)%approach, a_ref), &
                     rel(res%states(1)%contacts*deck%pixel**2, c_ref), int_str(res%nsteps)//" steps")
               end if
            end if
            call add_series(series, case_label, times, errors, dashed=.true.)
            call add_series(series, "Pareto front, "//case_label, pack(times, front(times, errors)), &
               pack(errors, front(times, errors)), markers=.false.)
            deallocate(times, errors)
      end subroutine frontier_case

      real(dp) function rel(x, reference)
         real(dp), intent(in) :: x, reference
         rel = abs(x - reference)/abs(reference)
      end function rel

      subroutine timed_solve(problem, opts, out, seconds)
         type(contact_problem), intent(in) :: problem
         type(contact_options), intent(in) :: opts
         type(contact_result), intent(out) :: out
         real(dp), intent(out) :: seconds
         real(dp) :: s0, s1
         call wall_clock(s0)
         call solve_contact(problem, opts, out, status)
         call wall_clock(s1)
         seconds = s1 - s0
      end subroutine timed_solve

      !> A row of the table; a time below 0: failed; an error below 0: not estimated.
      !> Points with an area error go on the figure (an error of 0, the reference, at
      !> 1e-16: the figure is logarithmic).
      subroutine frontier_row(name, seconds, approach_error, area_error, note)
         character(len=*), intent(in) :: name, note
         real(dp), intent(in) :: seconds, approach_error, area_error
         character(len=:), allocatable :: ta, tc
         ta = "-"
         tc = "-"
         if (approach_error >= 0) ta = real_str(approach_error, 2)
         if (area_error >= 0) tc = real_str(area_error, 2)
         if (seconds < 0) then
            write(output_unit, '(a)') "| "//case_label//" | "//name//" | failed | | | "//note//" |"
         else
            write(output_unit, '(a)') "| "//case_label//" | "//name//" | "//real_str(seconds, 3)// &
               " | "//ta//" | "//tc//" | "//note//" |"
            if (area_error >= 0) then
               times = [times, max(seconds, 1.0e-6_dp)]
               errors = [errors, max(area_error, 1.0e-16_dp)]
            end if
         end if
         flush(output_unit)
      end subroutine frontier_row

      !> The points no other point beats in both time and error.
      function front(t, e) result(keep)
         real(dp), intent(in) :: t(:), e(:)
         logical :: keep(size(t))
         integer :: a, b
         keep = .true.
         do a = 1, size(t)
            do b = 1, size(t)
               if (b /= a .and. t(b) <= t(a) .and. e(b) <= e(a) .and. (t(b) < t(a) .or. e(b) < e(a))) keep(a) = .false.
            end do
         end do
      end function front

      !> The uncoupled model at load F: load(d) = sum_{g<d} (d - g)/c increases with d and
      !> is linear between sorted gaps, (k d - S_k)/c on [g_k, g_k+1] with S_k the sum of
      !> the k smallest: the approach is d = (c F + S_k)/k for the last k whose g_k gives a
      !> load below F; the area, then, is k pixels (one sort, no iteration).
      subroutine uncoupled_at(target, d, a)
         real(dp), intent(in) :: target
         real(dp), intent(out) :: d, a
         real(dp) :: cself, partial
         real(dp), allocatable :: gaps(:)
         integer, allocatable :: order(:)
         integer :: k
         gaps = reshape(g0, [np*np])
         allocate(order(size(gaps)))
         call merge_sort_index(gaps, order)
         gaps = gaps(order)
         cself = (surface_compliance(deck%young(1), deck%poisson(1), deck%pixel) + &
            surface_compliance(deck%young(2), deck%poisson(2), deck%pixel))*love_influence(0, 0) + &
            3/spring_stiffness(deck%young(3), deck%poisson(3), deck%pixel, deck%pixel)
         partial = 0
         do k = 1, size(gaps)
            partial = partial + gaps(k)
            ! Load at the next gap with k pixels carrying: (k g_{k+1} - S_k)/c.
            if (k == size(gaps)) exit
            if ((k*gaps(k + 1) - partial)/cself >= target) exit
         end do
         d = (cself*target + partial)/k
         a = k*deck%pixel**2
      end subroutine uncoupled_at

      !> McCool's area at the nominal pressure F / (NP d)^2, on the composite roughness.
      subroutine mccool_at(target, a)
         real(dp), intent(in) :: target
         real(dp), intent(out) :: a
         type(mccool_parameters) :: mc
         real(dp) :: ar(1), nominal
         nominal = (np*deck%pixel)**2
         mc = mccool_surface(deck%lower + flip_upper(deck%upper), deck%pixel)
         call mccool_area(mc, composite_modulus(deck%young(1:2), deck%poisson(1:2)), nominal, [target/nominal], ar)
         a = ar(1)
      end subroutine mccool_at
   end subroutine bench_frontier

   function bench_frontier_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_option("--np", "N", "pixels per side of the benchmark surface (default 256)", lower=16), &
         real_list_option("--contact", "F1,...", "contact fractions in percent (default 1,5)", lower=0.0_dp), &
         text_option("--svg", "FILE", "write the figure (log time against log area error, Pareto front)"), &
         text_option("--deck", "FILE", "a thesis deck solved the same ways, the Appendix B program too (default "// &
            "input/sphere_d1.deck, built in: the bench runs from any directory)"), &
         flag_option("--no-deck", "the benchmark surface only (no thesis deck, no Appendix B program)"), &
         real_option("--deck-load", "F", "the deck's load in nN (default 1000)", lower=0.0_dp, closed="()")]
   end function bench_frontier_table

   !> `femcod bench cg`: the fixed-load solver on self-affine surfaces of growing size at
   !> the mean pressures that give about the requested contact fractions, side by side with
   !> the peer solvers when a Python with them is given.
   subroutine bench_cg(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer, allocatable :: sizes(:)
      real(dp), allocatable :: fractions(:), g0(:, :)
      character(len=:), allocatable :: python, path, wisdom
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: res
      type(parsed_options) :: parsed
      real(dp) :: tol, estar, slope, pressure, load, length, peak
      integer :: i, n, k, np
      logical :: loaded
      character(len=512) :: line
      character(len=*), parameter :: peers(2) = [character(len=16) :: "aspher", "contactmechanics"]
      sizes = [512, 1024]
      fractions = [1.0_dp, 5.0_dp, 10.0_dp]
      tol = 1.0e-8_dp
      python = ""
      wisdom = ""
      if (help_requested(args)) then
         write(output_unit, '(a)') &
            "usage: femcod bench cg [--np 512,1024] [--contact 1,5,10] [--tol 1e-8] [--peers PYTHON]", &
            "The fixed-load solver (--solver cg) on the benchmark surface: self-affine, Hurst 0.8, rms 3 nm,", &
            "5 um square, E = 200 GPa, nu = 0.25, against a rigid flat (seed 1), at each NP of --np. The mean", &
            "pressure for a contact fraction f (percent) is f/100 * E* h'rms / 2 (the linear law with", &
            "kappa = 2, h'rms the surface's own rms slope); the fraction reached is printed. Each load is", &
            "solved from a cold start. The peers (aspher at every NP, contactmechanics at NP <= 512) run on", &
            "the same gaps, pressures and tolerance. --fftw-wisdom: the first run on a size pays the planning", &
            "inside its wall time.", ""
         call print_lines(option_help(bench_cg_table(), ""))
         write(output_unit, '(a)') "Run it with the release build.", &
            "Columns: NP, target %, solver, wall (s), iterations, residual, contact %, peak RSS (MB)."
         return
      end if
      if (.not. bench_arguments(bench_cg_table(), args, "femcod bench cg", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--np", sizes)
      call get_option(parsed, "--contact", fractions)
      call get_option(parsed, "--tol", tol)
      call get_option(parsed, "--peers", python)
      call get_option(parsed, "--fftw-wisdom", wisdom)
      call require_peers(python, "cg", code)
      if (code /= 0) return
      associate(method => options%cg)
         if (option_given(parsed, "--nested")) method%nested = switch("--nested")
         if (option_given(parsed, "--restart")) method%restart_on_entry = switch("--restart")
         if (option_given(parsed, "--precondition")) method%precondition = switch("--precondition")
         if (option_given(parsed, "--polak-ribiere")) method%polak_ribiere = switch("--polak-ribiere")
         call get_option(parsed, "--powell", method%powell_restart)
         call get_option(parsed, "--entry", method%entry_scale)
         call get_option(parsed, "--coarsest", method%coarsest)
         call get_option(parsed, "--coarse-tol", method%coarse_tol)
         call get_option(parsed, "--single-until", method%single_until)
         call get_option(parsed, "--direct", method%direct_corrections)
         call get_option(parsed, "--split", method%split_radius)
         call get_option(parsed, "--split-cell", method%split_cell)
         call get_option(parsed, "--split-budget", method%split_budget)
         call get_option(parsed, "--split-tolerance", method%split_tolerance)
         method%tol = tol
         method%max_iterations = 5000
         if (len(wisdom) > 0) then
            method%measure_plans = .true.
            call load_wisdom(wisdom, loaded)
         end if
      end associate
      options%solver = "cg"
      write(output_unit, '(a)') "| NP | target % | solver | wall (s) | iterations | residual | contact % "// &
         "| peak RSS (MB) | status |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|"
      do n = 1, size(sizes)
         np = sizes(n)
         length = BENCH_LENGTH
         call benchmark_surface(np, "bench cg", deck, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench cg: "//status%message
            code = status%code
            return
         end if
         call linear_law(deck, estar, slope, g0)
         path = "femcod-bench-gaps.f64"
         if (len(python) > 0) call write_peer_gaps(path, g0)
         ! The peers read the file: the bench's own copy of the gaps is not the solver's.
         deallocate(g0)
         do k = 1, size(fractions)
            pressure = fractions(k)/100*estar*slope/2
            load = pressure*length**2
            options%loads = [load]
            options%max_contacts = 0
            call reset_peak()
            call solve_contact(deck, options, res, status)
            peak = peak_mb()
            if (len(wisdom) > 0 .and. status%code == 0) call save_wisdom(wisdom, status)
            if (status%code /= 0) then
               write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(fractions(k), 1)//" | femcod cg | | | | | | "// &
                  status%message//" |"
               status = status_type()
               cycle
            end if
            write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(fractions(k), 1)//" | femcod cg | "// &
               fixed_str(res%wall_seconds, 2)//" | "//int_str(res%states(1)%iterations)//" (+"// &
               int_str(res%states(1)%coarse_iterations)//" coarse, "//int_str(res%states(1)%convolutions)// &
               " fresh, "//int_str(res%states(1)%split_corrections)//" split) | "// &
               real_str(res%states(1)%residual, 2)//" | "// &
               fixed_str(100*res%states(1)%contacts/real(np, dp)**2, 2)//" | "//fixed_str(peak, 0)//" | converged |"
            flush(output_unit)
            if (len(python) == 0) cycle
            do i = 1, size(peers)
               if (trim(peers(i)) == "contactmechanics" .and. np > 512) cycle
               line = peer_line(python, trim(peers(i)), path, np, deck%pixel, estar, pressure, tol)
               call peer_row(np, fractions(k), line)
            end do
         end do
         if (len(python) > 0) call remove_file_quietly(path)
      end do
   contains
      logical function switch(name)
         character(len=*), intent(in) :: name
         character(len=:), allocatable :: v
         v = ""
         call get_option(parsed, name, v)
         switch = v == "on"
      end function switch
   end subroutine bench_cg

   !> `femcod bench convolution`: one Love convolution on NP x NP (zero-padded (2NP)^2
   !> transforms) with FFTW's estimated and measured plans: set-up time (planning, kernel
   !> spectrum), time per convolution in double and float32, the float32 result's largest
   !> difference from double, and double's largest difference from the direct sum
   !> sum_k I(p - k) F(k) at three pixels (corner, centre, edge; O(NP^2) each), all relative
   !> to the largest value. The field is uniform random on [0, 1) (seed 1).
   subroutine bench_convolution(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer, allocatable :: sizes(:)
      real(dp), allocatable :: table(:, :), field(:, :), double(:, :), single(:, :)
      type(love_convolution) :: conv
      type(random_stream) :: stream
      real(dp) :: t0, t1, setup, t_double, t_single, err_single, err_direct, direct, scale
      integer :: n, np, repeat, k, plans, probe(2, 3), kk, l
      type(parsed_options) :: parsed
      type(status_type) :: status
      sizes = [512, 1024, 2048]
      repeat = 5
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod bench convolution [--np 512,1024,2048] [--repeat 5]", &
            "One Love-kernel convolution on NP x NP by zero-padded (2NP)^2 FFTs, with FFTW's estimated and", &
            "measured plans (measured here, no wisdom): set-up time, time per convolution in double and", &
            "float32 (mean of --repeat, after one untimed), float32's largest difference from double, and", &
            "double's largest difference from the direct sum at three pixels, relative to the largest value.", ""
         call print_lines(option_help(bench_convolution_table(), ""))
         write(output_unit, '(a)') "Run it with the release build."
         return
      end if
      if (.not. bench_arguments(bench_convolution_table(), args, "femcod bench convolution", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--np", sizes)
      call get_option(parsed, "--repeat", repeat)
      write(output_unit, '(a)') "| NP | plans | set-up (s) | double (s) | float32 (s) | float32 - double "// &
         "| double - direct sum |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|"
      do n = 1, size(sizes)
         np = sizes(n)
         allocate(table(0:np - 1, 0:np - 1), field(np, np), double(np, np), single(np, np))
         table = offset_table(np)
         call seed_stream(stream, 1)
         do l = 1, np
            do k = 1, np
               call uniform(stream, field(k, l))
            end do
         end do
         probe = reshape([1, 1, (np + 1)/2, (np + 1)/2, np, (np + 1)/3], [2, 3])
         do plans = 1, 2
            call wall_clock(t0)
            call convolution_setup(conv, table, single=.true., measure=plans == 2)
            call wall_clock(t1)
            setup = t1 - t0
            ! One untimed convolution in each precision first: the first touches the
            ! buffers and starts the threads.
            call convolution_apply(conv, field, double)
            call convolution_apply_single(conv, field, single)
            call wall_clock(t0)
            do k = 1, repeat
               call convolution_apply(conv, field, double)
            end do
            call wall_clock(t1)
            t_double = (t1 - t0)/repeat
            call wall_clock(t0)
            do k = 1, repeat
               call convolution_apply_single(conv, field, single)
            end do
            call wall_clock(t1)
            t_single = (t1 - t0)/repeat
            call convolution_free(conv)
            scale = maxval(abs(double))
            err_single = maxval(abs(single - double))/scale
            err_direct = 0
            do kk = 1, 3
               direct = 0
               do l = 1, np
                  do k = 1, np
                     direct = direct + table(abs(probe(1, kk) - k), abs(probe(2, kk) - l))*field(k, l)
                  end do
               end do
               err_direct = max(err_direct, abs(double(probe(1, kk), probe(2, kk)) - direct)/scale)
            end do
            write(output_unit, '(a)') "| "//int_str(np)//" | "//trim(merge("estimated", "measured ", plans == 1))// &
               " | "//fixed_str(setup, 3)//" | "//fixed_str(t_double, 4)//" | "//fixed_str(t_single, 4)//" | "// &
               real_str(err_single, 2)//" | "//real_str(err_direct, 2)//" |"
            flush(output_unit)
         end do
         deallocate(table, field, double, single)
      end do
   end subroutine bench_convolution

   !> One table row from the peer script's line "peer seconds iterations residual fraction
   !> peak status" (fraction as a share, printed in percent).
   !> The gaps (nm) for the peers, NP*NP float64 in Fortran order (app/femcod_peers.py).
   subroutine write_peer_gaps(path, g0)
      character(len=*), intent(in) :: path
      real(dp), intent(in) :: g0(:, :)
      integer :: unit
      open(newunit=unit, file=path, access="stream", form="unformatted", status="replace", action="write")
      write(unit) g0
      close(unit)
   end subroutine write_peer_gaps

   subroutine remove_file_quietly(path)
      character(len=*), intent(in) :: path
      integer :: unit, ios
      open(newunit=unit, file=path, status="old", iostat=ios)
      if (ios == 0) close(unit, status="delete")
   end subroutine remove_file_quietly

   !> One peer's answer line (app/femcod_peers.py) on the gaps in `path`, or
   !> "PEER - - - - - failed -" when it gave none.
   function peer_line(python, peer, path, np, pixel, estar, pressure, tol, extra) result(line)
      character(len=*), intent(in) :: python, peer, path
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, estar, pressure, tol
      !> More arguments for the peer (tamaas-adhesion: LAW W RANGE).
      character(len=*), intent(in), optional :: extra
      character(len=512) :: line
      character(len=:), allocatable :: more
      character(len=*), parameter :: peer_out = "femcod-bench-peer.txt"
      integer :: unit, ios
      more = ""
      if (present(extra)) more = " "//extra
      call execute_command_line(python//" "//peers_script()//" "//peer//" "//path//" "//int_str(np)//" "// &
         real_str(pixel, 16)//" "//real_str(estar, 16)//" "//real_str(pressure, 16)//" "//real_str(tol, 3)// &
         more//" > "//peer_out, exitstat=ios)
      line = peer//" - - - - - failed -"
      open(newunit=unit, file=peer_out, action="read", status="old", iostat=ios)
      if (ios == 0) then
         read(unit, '(a)', iostat=ios) line
         close(unit, status="delete")
      end if
   end function peer_line

   subroutine peer_row(np, target, line)
      integer, intent(in) :: np
      real(dp), intent(in) :: target
      character(len=*), intent(in) :: line
      character(len=64) :: words(7)
      real(dp) :: fraction
      integer :: ios
      words = "-"
      read(line, *, iostat=ios) words
      read(words(5), *, iostat=ios) fraction
      if (ios == 0) words(5) = fixed_str(100*fraction, 2)
      write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(target, 1)//" | "//trim(words(1))//" | "// &
         trim(words(2))//" | "//trim(words(3))//" | "//trim(words(4))//" | "//trim(words(5))//" | "// &
         trim(words(6))//" | "//trim(words(7))//" |"
      flush(output_unit)
   end subroutine peer_row

   subroutine row(problem, np, res, solver, error, reference, peak)
      character(len=*), intent(in) :: problem, solver, reference
      integer, intent(in) :: np
      type(contact_result), intent(in) :: res
      real(dp), intent(in) :: error, peak
      integer :: contacts
      contacts = size(res%contact_i)
      write(output_unit, '(a)') "| "//problem//" | "//int_str(np)//" | "//int_str(contacts)//" | "//solver//" | "// &
         real_str(res%wall_seconds, 3)//" | "//real_str(1000*res%wall_seconds/max(res%nsteps, 1), 3)//" | "// &
         real_str(peak, 3)//" | "//real_str(error, 2)//" | "//reference//" |"
      flush(output_unit)
   end subroutine row

   !> Segedin's rigid sphere R = 15 nm on E = 200 GPa, nu = 0.25: approach at load f.
   real(dp) function segedin(f)
      real(dp), intent(in) :: f
      real(dp) :: a
      call segedin_sphere(f, 15.0_dp, 200/(1 - 0.25_dp**2), a, segedin)
   end function segedin

   !> Reset the kernel's peak-RSS counter of this process (Linux /proc/self/clear_refs).
   subroutine reset_peak()
      integer :: unit, ios
      open(newunit=unit, file="/proc/self/clear_refs", action="write", iostat=ios)
      if (ios == 0) then
         write(unit, '(a)', iostat=ios) "5"
         close(unit, iostat=ios)
      end if
   end subroutine reset_peak

   !> Peak resident memory (MB) since the last reset, from /proc/self/status (VmHWM).
   real(dp) function peak_mb()
      integer :: unit, ios, kb
      character(len=256) :: line
      peak_mb = -1
      open(newunit=unit, file="/proc/self/status", action="read", iostat=ios)
      if (ios /= 0) return
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:6) == "VmHWM:") then
            read(line(7:), *, iostat=ios) kb
            if (ios == 0) peak_mb = kb/1024.0_dp
            exit
         end if
      end do
      close(unit)
   end function peak_mb
   !> `femcod bench adhesion`: the adhesive solver's resolution study (issue 20's checks).
   !> 1. The Maugis-Dugdale sphere: the least load over an unloading path against the
   !>    theory's pull-off (analytic/maugis_minimum) at lambda = 0.1, 1, 2, pixels halved,
   !>    with the first-order extrapolation of each pair. 2. The Contact Mechanics
   !>    Challenge's interaction (E* = 25 MPa, W = 0.05 J/m^2, exponential range 2.071 nm)
   !>    on a self-affine surface at 250 kPa, pixels of 4, 2, 1 nm (2 x 2 averages).
   subroutine bench_adhesion(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      real(dp), parameter :: pi = acos(-1.0_dp), work = 0.01_dp, young = 1
      real(dp), parameter :: lambdas(3) = [0.1_dp, 1.0_dp, 2.0_dp], radii(3) = [100.0_dp, 1000.0_dp, 1000.0_dp], &
         boxes(3) = [64.0_dp, 128.0_dp, 128.0_dp]
      type(parsed_options) :: parsed
      type(status_type) :: status
      type(contact_problem) :: deck, fine
      type(contact_options) :: options
      type(contact_result) :: res
      type(scene_spec) :: spec
      real(dp), allocatable :: pixels(:), path(:)
      real(dp) :: theory, pmin, previous, t0, t1, target, w, radius, limit
      character(len=:), allocatable :: python
      logical :: full
      integer :: c, k, np, n, i, j, cmc_np
      full = .false.
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod bench adhesion [--full]", &
            "1. A rigid paraboloid on a flat (E* = 1 GPa, W = 0.01 J/m^2, Dugdale range for the Maugis", &
            "   parameter lambda = 0.1, 1, 2; R = 100, 1000, 1000 nm; boxes of 64, 128, 128 nm) loaded to", &
            "   1 nm and unloaded in steps of 0.025 or 0.05 nm past the pull-off, pixels of 2, 1, 0.5 nm", &
            "   (and 0.25 with --full): the least load over pi W R against Maugis-Dugdale (Maugis 1992),", &
            "   the first-order extrapolation 2 P(d) - P(2d), iterations, wall time.", &
            "2. The Contact Mechanics Challenge's interaction, E* = 25 MPa, W = 0.05 J/m^2, exponential", &
            "   range 2.071 nm, on a self-affine surface (H = 0.8, rms 40 nm, 256 nm square, seed 1) and", &
            "   its 2 x 2 averages (pixels 1, 2, 4 nm; 512^2 at 0.5 nm with --full): loaded in approach", &
            "   steps of 2.5 nm to 250 kPa mean pressure; area, attractive area and mean gap there", &
            "   (linear between the two approaches around it), the convexity ratio, iterations, time.", &
            "3. With --peers PYTHON: the lambda = 0.5 sphere (R = 100 nm, d = 1 nm, 64^2) on a periodic cell at", &
            "   approaches 1, 0.5, 0.25 nm, W = 0.01 and 0, femcod beside tamaas' Maugis functional at the same", &
            "   mean gap (app/femcod_peers.py; tamaas from the undeformed surfaces, femcod along the path);", &
            "   then the rough surface of part 2 as a periodic cell with the CMC interaction at 10, 20, 30 nm,", &
            "   each approach from the undeformed surfaces in both.", ""
         call print_lines(option_help(bench_adhesion_table(), ""))
         write(output_unit, '(a)') "Run it with the release build."
         return
      end if
      if (.not. bench_arguments(bench_adhesion_table(), args, "femcod bench adhesion", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--full", full)
      python = ""
      call get_option(parsed, "--peers", python)
      call require_peers(python, "adhesion", code)
      if (code /= 0) return
      options%solver = "cg"
      options%adhesion = "dugdale"
      options%work = work
      options%cg = cg_settings()
      options%cg%max_iterations = 20000
      allocate(options%loads(0))
      write(output_unit, '(a)') "Maugis-Dugdale sphere: least load over pi W R along the unloading path", ""
      write(output_unit, '(a)') "| lambda | R (nm) | d (nm) | NP | least load | Maugis-Dugdale | error | "// &
         "2 P(d) - P(2d) | its error | iterations | wall (s) |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|---|---|"
      pixels = [2.0_dp, 1.0_dp, 0.5_dp]
      if (full) pixels = [pixels, 0.25_dp]
      do c = 1, size(lambdas)
         radius = radii(c)
         theory = maugis_pull_off(lambdas(c))
         options%range = work/lambdas(c)*(9*radius/(2*pi*work*young**2))**(1.0_dp/3)
         if (c == 1) then
            path = [1.0_dp, (-0.05_dp - 0.025_dp*k, k = 0, 12)]
         else
            path = [1.0_dp, (-0.2_dp - 0.05_dp*k, k = 0, 7)]
         end if
         options%approaches = path
         do k = 1, size(pixels)
            np = nint(boxes(c)/pixels(k))
            deck = paraboloid_problem(np, pixels(k), radius, young)
            call wall_clock(t0)
            call solve_contact(deck, options, res, status)
            call wall_clock(t1)
            if (status%code /= 0) then
               write(error_unit, '(a)') "femcod bench adhesion: "//status%message
               code = status%code
               return
            end if
            pmin = minval(res%states%load)/(pi*work*radius)
            if (k == 1) then
               write(output_unit, '(a)') "| "//fixed_str(lambdas(c), 1)//" | "//int_str(nint(radius))//" | "// &
                  fixed_str(pixels(k), 2)//" | "//int_str(np)//" | "//fixed_str(pmin, 4)//" | "// &
                  fixed_str(theory, 4)//" | "//real_str(abs(pmin/theory - 1), 2)//" | | | "// &
                  int_str(sum(res%states%iterations))//" | "//fixed_str(t1 - t0, 2)//" |"
            else
               write(output_unit, '(a)') "| "//fixed_str(lambdas(c), 1)//" | "//int_str(nint(radius))//" | "// &
                  fixed_str(pixels(k), 2)//" | "//int_str(np)//" | "//fixed_str(pmin, 4)//" | "// &
                  fixed_str(theory, 4)//" | "//real_str(abs(pmin/theory - 1), 2)//" | "// &
                  fixed_str(2*pmin - previous, 4)//" | "//real_str(abs((2*pmin - previous)/theory - 1), 2)//" | "// &
                  int_str(sum(res%states%iterations))//" | "//fixed_str(t1 - t0, 2)//" |"
            end if
            previous = pmin
         end do
      end do
      ! 2. The Contact Mechanics Challenge's interaction on a self-affine surface.
      cmc_np = merge(512, 256, full)
      spec%kind = "self-affine"
      spec%np = cmc_np
      spec%pixel = 256.0_dp/cmc_np
      spec%hurst = 0.8_dp
      spec%rms = 40
      spec%seed = 1
      spec%young = 0.025_dp
      spec%poisson = 0
      spec%shape_on = "lower"
      spec%rigid = "upper"
      spec%label = "bench adhesion"
      spec%matrix_file = ""
      spec%maxcont = cmc_np**2
      call build_problem(spec, fine, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod bench adhesion: "//status%message
         code = status%code
         return
      end if
      target = 2.5e-4_dp
      options%adhesion = "exponential"
      options%work = 0.05_dp
      options%range = 2.071_dp
      write(output_unit, '(a)') "", "Contact Mechanics Challenge interaction (E* = 25 MPa, W = 0.05 J/m^2, "// &
         "exponential range 2.071 nm), self-affine surface, 250 kPa", ""
      write(output_unit, '(a)') "| d (nm) | NP | convexity d^2 W/R^2 : k_pixel | approach (nm) | contact % | "// &
         "attractive % | mean gap (nm) | states | iterations | wall (s) |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|---|"
      n = cmc_np
      do while (n >= 64)
         call level_deck(fine, n, "average", deck, status)
         if (status%code /= 0) exit
         ! Loading from 0 in steps of 2.5 nm to 20 nm, 40 nm, ... until the mean pressure
         ! passes the target; i the first state past it.
         limit = 20
         do
            path = [(2.5_dp*k, k = 0, nint(limit/2.5_dp))]
            options%approaches = path
            call wall_clock(t0)
            call solve_contact(deck, options, res, status)
            call wall_clock(t1)
            if (status%code /= 0) exit
            i = findloc(res%states%load/(real(deck%np, dp)*deck%pixel)**2 >= target, .true., 1)
            if (i > 0 .or. limit > 300) exit
            limit = 2*limit
         end do
         if (status%code /= 0) exit
         if (i == 0) i = size(path)
         j = max(1, i - 1)
         associate(a => res%states(j), b => res%states(i))
            w = 1
            if (b%load /= a%load) w = (target*(real(deck%np, dp)*deck%pixel)**2 - a%load)/(b%load - a%load)
            write(output_unit, '(a)') "| "//fixed_str(deck%pixel, 1)//" | "//int_str(deck%np)//" | "// &
               fixed_str(convexity(deck), 2)//" | "//fixed_str(a%approach + w*(b%approach - a%approach), 2)//" | "// &
               fixed_str(100*(a%contacts + w*(b%contacts - a%contacts))/real(deck%np, dp)**2, 2)//" | "// &
               fixed_str(100*(a%attractive + w*(b%attractive - a%attractive))/real(deck%np, dp)**2, 2)//" | "// &
               fixed_str(a%mean_gap + w*(b%mean_gap - a%mean_gap), 2)//" | "//int_str(i)//" | "// &
               int_str(sum(res%states%iterations))//" | "//fixed_str(t1 - t0, 2)//" |"
         end associate
         n = n/2
         if (n < 64) exit
      end do
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod bench adhesion: "//status%message
         code = status%code
         return
      end if
      if (len(python) > 0) call side_by_side()
   contains
      !> Part 3: femcod and tamaas on the periodic sphere at the same mean gaps.
      subroutine side_by_side()
         real(dp), parameter :: approaches(3) = [1.0_dp, 0.5_dp, 0.25_dp], works(3) = [0.01_dp, 0.01_dp, 0.0_dp]
         character(len=*), parameter :: laws(3) = [character(len=11) :: "dugdale", "exponential", "dugdale"]
         character(len=*), parameter :: path = "femcod-bench-gaps.f64"
         character(len=512) :: line
         character(len=64) :: words(8)
         real(dp), allocatable :: g0(:, :)
         real(dp) :: range
         integer :: iw, ia, ios
         deck = paraboloid_problem(64, 1.0_dp, 100.0_dp, young)
         g0 = transpose(reshape(initial_gaps(deck%lower, deck%upper), [64, 64]))
         call write_peer_gaps(path, g0)
         write(output_unit, '(a)') "", "Periodic sphere (R = 100 nm, d = 1 nm, 64^2), femcod beside tamaas "// &
            "(Maugis or exponential functional, PolonskyKeerRey on gaps)", "", &
            "| law | W (J/m^2) | range (nm) | approach (nm) | femcod load (nN) | tamaas load (nN) | "// &
            "difference / (pi W R) | femcod contact % | tamaas contact % | tamaas (s) |", &
            "|---|---|---|---|---|---|---|---|---|---|"
         do iw = 1, size(works)
            ! Dugdale at lambda = 0.5; the exponential law with the same work and range.
            range = 0.01_dp/0.5_dp*(9*100/(2*pi*0.01_dp*young**2))**(1.0_dp/3)
            options = contact_options()
            options%solver = "cg"
            options%boundary = "periodic"
            allocate(options%loads(0))
            options%adhesion = laws(iw)
            options%work = works(iw)
            options%range = range
            options%cg%tol = 1.0e-10_dp
            options%approaches = approaches
            call solve_contact(deck, options, res, status)
            if (status%code /= 0) then
               write(error_unit, '(a)') "femcod bench adhesion: "//status%message
               code = status%code
               return
            end if
            do ia = 1, size(approaches)
               line = peer_line(python, "tamaas-adhesion", path, 64, 1.0_dp, young, sum(g0)/64**2 - approaches(ia), &
                  1.0e-10_dp, trim(laws(iw))//" "//real_str(works(iw), 16)//" "//real_str(range, 16))
               words = "-"
               read(line, *, iostat=ios) words
               read(words(8), *, iostat=ios) w
               if (ios /= 0) w = huge(1.0_dp)
               read(words(5), *, iostat=ios) theory
               write(output_unit, '(a)') "| "//trim(laws(iw))//" | "//fixed_str(works(iw), 2)//" | "// &
                  fixed_str(range, 3)//" | "//fixed_str(approaches(ia), 2)//" | "// &
                  fixed_str(res%states(ia)%load, 4)//" | "//fixed_str(w, 4)//" | "// &
                  fixed_str((res%states(ia)%load - w)/(pi*0.01_dp*100), 4)//" | "// &
                  fixed_str(100*res%states(ia)%contacts/64.0_dp**2, 2)//" | "//fixed_str(100*theory, 2)//" | "// &
                  trim(words(2))//" |"
               flush(output_unit)
            end do
         end do
         ! The rough surface of part 2 (1 nm pixels) as a periodic cell, each mean gap
         ! solved from the undeformed surfaces by both (one approach per femcod run).
         write(output_unit, '(a)') "", "The same rough surface as a periodic cell, CMC interaction, each "// &
            "approach from the undeformed surfaces", "", &
            "| approach (nm) | femcod load (nN) | tamaas load (nN) | difference / load | femcod contact % | "// &
            "tamaas contact % | femcod (s) | tamaas (s) |", "|---|---|---|---|---|---|---|---|"
         g0 = transpose(reshape(initial_gaps(fine%lower, fine%upper), [fine%np, fine%np]))
         call write_peer_gaps(path, g0)
         do ia = 1, 3
            options = contact_options()
            options%solver = "cg"
            options%boundary = "periodic"
            allocate(options%loads(0))
            options%adhesion = "exponential"
            options%work = 0.05_dp
            options%range = 2.071_dp
            options%cg%max_iterations = 20000
            options%approaches = [10.0_dp*ia]
            call wall_clock(t0)
            call solve_contact(fine, options, res, status)
            call wall_clock(t1)
            if (status%code /= 0) then
               write(error_unit, '(a)') "femcod bench adhesion: "//status%message
               code = status%code
               return
            end if
            line = peer_line(python, "tamaas-adhesion", path, fine%np, fine%pixel, fine%young(1), &
               sum(g0)/real(fine%np, dp)**2 - options%approaches(1), 1.0e-8_dp, "exponential 0.05 2.071")
            words = "-"
            read(line, *, iostat=ios) words
            read(words(8), *, iostat=ios) w
            if (ios /= 0) w = huge(1.0_dp)
            read(words(5), *, iostat=ios) theory
            write(output_unit, '(a)') "| "//fixed_str(options%approaches(1), 1)//" | "// &
               fixed_str(res%states(1)%load, 3)//" | "//fixed_str(w, 3)//" | "// &
               real_str(abs(res%states(1)%load - w)/abs(w), 2)//" | "// &
               fixed_str(100*res%states(1)%contacts/real(fine%np, dp)**2, 2)//" | "//fixed_str(100*theory, 2)// &
               " | "//fixed_str(t1 - t0, 2)//" | "//trim(words(2))//" |"
            flush(output_unit)
         end do
         call remove_file_quietly(path)
      end subroutine side_by_side

      real(dp) function convexity(problem)
         type(contact_problem), intent(in) :: problem
         convexity = pixel_stiffness_ratio(problem, options%work, options%range)
      end function convexity
   end subroutine bench_adhesion

   function bench_adhesion_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [flag_option("--full", "add the 0.25 nm sphere grids and the 512^2 rough grid (minutes more)"), &
         text_option("--peers", "PYTHON", "a Python with tamaas installed: part 3, tamaas beside femcod")]
   end function bench_adhesion_table

end module femcod_bench
