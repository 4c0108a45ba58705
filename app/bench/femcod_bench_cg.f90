!> `femcod bench cg`: the fixed-load solver against the event-exact answer and the peers, speed
!> against error.
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_cg
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec
   use femcod_contact_result, only: contact_result, cg_state_diagnostics, cg_work
   use femcod_solver_options, only: contact_options, &
      SOLVER_CG
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, real_option, integer_option, text_option, &
      choice_option, real_list_option, integer_list_option, get_option, option_given
   use femcod_wisdom, only: load_wisdom, save_wisdom
   use femcod_output_guard, only: OUTPUT_WISDOM
   use femcod_bench_common, only: guard_bench_files, bench_arguments, surface_for_peers, require_peers, &
      remove_file_quietly, peer_line, peer_row, reset_peak, peak_mb, BENCH_LENGTH, options_refused, bare_pair_seconds
   implicit none
   private
   public :: bench_cg

contains

   !> `femcod bench cg`: the fixed-load solver on self-affine surfaces of growing size at
   !> the mean pressures that give about the requested contact fractions, side by side with
   !> the peer solvers when a Python with them is given.
   subroutine bench_cg(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer, allocatable :: sizes(:)
      real(dp), allocatable :: fractions(:)
      character(len=:), allocatable :: python, path, wisdom
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: res
      type(parsed_options) :: parsed
      real(dp) :: tol, estar, slope, pressure, load, length, peak, pair
      integer :: i, n, k, np
      type(string_type), allocatable :: limit_rows(:)
      character(len=:), allocatable :: row
      logical :: loaded, approach_rows
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
            "solved from a cold start. Each is solved again under displacement control at the approach it", &
            "reached (--approach, cold start; the load it gives against the requested one, and its wall time", &
            "against the load solve's). The peers (aspher at every NP, contactmechanics at NP <= 512) run on", &
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
      approach_rows = .true.
      if (option_given(parsed, "--approach")) approach_rows = switch("--approach")
      call require_peers(python, "cg", code)
      ! The wisdom file is read and brought up to date: it must be FFTW wisdom if it exists.
      if (len(wisdom) > 0) call guard_bench_files([string_type(wisdom), string_type(wisdom//".float32")], &
         OUTPUT_WISDOM, "cg", code)
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
      options%solver = SOLVER_CG
      if (options_refused(options, "femcod bench cg")) then
         code = 2
         return
      end if
      write(output_unit, '(a)') "| NP | target % | solver | wall (s) | iterations | residual | contact % "// &
         "| peak RSS (MB) | status |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|"
      allocate(limit_rows(0))
      do n = 1, size(sizes)
         np = sizes(n)
         length = BENCH_LENGTH
         pair = bare_pair_seconds(2*np, measure=.true., repeat=5)
         call surface_for_peers(np, "bench cg", python, deck, estar, slope, path, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench cg: "//status%message
            code = status%code
            return
         end if
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
            write(output_unit, '(a)') solver_row(np, fractions(k), "femcod cg", res, peak, "converged")
            flush(output_unit)
            ! (gfortran 12 cannot take the function's text inside the array constructor.)
            row = limit_row(np, fractions(k), res, pair)
            limit_rows = [limit_rows, string_type(row)]
            if (approach_rows) call approach_row(deck, options, np, fractions(k), res)
            if (len(python) == 0) cycle
            do i = 1, size(peers)
               if (trim(peers(i)) == "contactmechanics" .and. np > 512) cycle
               line = peer_line(python, trim(peers(i)), path, np, deck%pixel, estar, pressure, tol)
               call peer_row(np, fractions(k), line)
            end do
         end do
         if (len(python) > 0) call remove_file_quietly(path)
      end do
      write(output_unit, '(a)') "", "The solves above against one bare pair of FFTs of their transform grid "// &
         "((2NP)^2: FFTW's threaded 2-D r2c and c2r in double, measured plans, the planning not timed):", "", &
         "| NP | target % | wall (s) | bare pair (s) | solve in bare pairs | fine iterations + fresh "// &
         "| bare pairs a fine iteration (coarse grids in) |", "|---|---|---|---|---|---|---|"
      do k = 1, size(limit_rows)
         write(output_unit, '(a)') limit_rows(k)%s
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

   !> A row of the table against the bare pair: the solve of `res` in pairs of `pair` seconds
   !> and per finest-grid iteration and fresh convolution.
   function limit_row(np, fraction, res, pair) result(row)
      integer, intent(in) :: np
      real(dp), intent(in) :: fraction, pair
      type(contact_result), intent(in) :: res
      character(len=:), allocatable :: row
      type(cg_state_diagnostics) :: work
      integer :: fine
      work = cg_work(res, 1)
      fine = max(1, work%iterations + work%convolutions)
      row = "| "//int_str(np)//" | "//fixed_str(fraction, 1)//" | "//fixed_str(res%wall_seconds, 2)//" | "// &
         fixed_str(pair, 4)//" | "//fixed_str(res%wall_seconds/pair, 1)//" | "//int_str(work%iterations)//" + "// &
         int_str(work%convolutions)//" | "//fixed_str(res%wall_seconds/pair/fine, 2)//" |"
   end function limit_row

   !> The state of `loaded` (one load) solved again at its approach from a cold start (
   !> displacement control): a row with its wall time and iterations, and in the status
   !> column its load's relative difference from the load asked and its wall time over the
   !> load solve's.
   subroutine approach_row(deck, options, np, fraction, loaded)
      type(contact_problem), intent(inout) :: deck
      type(contact_options), intent(in) :: options
      integer, intent(in) :: np
      real(dp), intent(in) :: fraction
      type(contact_result), intent(in) :: loaded
      type(contact_options) :: by_approach
      type(contact_result) :: res
      type(status_type) :: status
      real(dp) :: peak
      by_approach = options
      deallocate(by_approach%loads)
      by_approach%approaches = [loaded%states(1)%approach]
      call reset_peak()
      call solve_contact(deck, by_approach, res, status)
      peak = peak_mb()
      if (status%code /= 0) then
         write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(fraction, 1)//" | femcod cg --approach "// &
            "| | | | | | "//status%message//" |"
         return
      end if
      write(output_unit, '(a)') solver_row(np, fraction, "femcod cg --approach", res, peak, "load "// &
         real_str(abs(res%states(1)%load/options%loads(1) - 1), 2)//" off, wall x"// &
         fixed_str(res%wall_seconds/loaded%wall_seconds, 2)//" the load solve's")
      flush(output_unit)
   end subroutine approach_row

   !> A table row of one solve of `res` (one state) on the NP^2 surface at the target
   !> `fraction` (percent): wall time, iterations (coarse grids, fresh convolutions and
   !> split corrections beside), residual, contact percent, peak RSS (MB), `remark`.
   function solver_row(np, fraction, solver, res, peak, remark) result(row)
      integer, intent(in) :: np
      real(dp), intent(in) :: fraction, peak
      character(len=*), intent(in) :: solver, remark
      type(contact_result), intent(in) :: res
      character(len=:), allocatable :: row
      type(cg_state_diagnostics) :: work
      work = cg_work(res, 1)
      row = "| "//int_str(np)//" | "//fixed_str(fraction, 1)//" | "//solver//" | "//fixed_str(res%wall_seconds, 2)// &
         " | "//int_str(work%iterations)//" (+"//int_str(work%coarse_iterations)//" coarse, "// &
         int_str(work%convolutions)//" fresh, "//int_str(work%split_corrections)//" split) | "// &
         real_str(work%residual, 2)//" | "//fixed_str(100*res%states(1)%contacts/real(np, dp)**2, 2)//" | "// &
         fixed_str(peak, 0)//" | "//remark//" |"
   end function solver_row

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
         choice_option("--approach", "on|off", "each state solved again at its approach (default on)"), &
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
end module femcod_bench_cg
