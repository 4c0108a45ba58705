!> `femcod bench`: the solvers against each other and against the thesis' published numbers
!> (the rough 512^2 surface, the verification decks of Tables 4.1 and 4.2, Segedin's sphere).
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_thesis
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem, THESIS_RIGID_FACTOR, verification_spec
   use femcod_contact_result, only: contact_result, cg_iterations_in_all, largest_cg_residual, &
      event_path_diagnostics, event_checks
   use femcod_solver_options, only: contact_options, solver_from_name
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type, int_str, real_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, flag_option, integer_option, get_option
   use femcod_thesis, only: TABLE_4_1_APPROACH, TABLE_4_2_APPROACH
   use femcod_bench_common, only: bench_arguments, row, segedin, reset_peak, peak_mb
   implicit none
   private
   public :: bench_thesis

contains

   subroutine bench_thesis(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(contact_problem) :: rough
      type(scene_spec) :: spec
      type(status_type) :: status
      type(contact_result) :: inc, leg
      type(event_path_diagnostics) :: checks
      type(contact_options) :: options
      type(parsed_options) :: parsed
      integer :: legacy_contacts, n, k
      logical :: full
      real(dp), allocatable :: cg_loads(:), cg_approach(:)
      real(dp) :: err, peak
      code = 0
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
            "       femcod bench tangential [--full] [--figure FILE] [--peers PYTHON]  (--help for more)", &
            "       femcod bench mpi [--np LIST] [--ranks LIST]  (--help for more; needs femcod-mpi)", &
            "       femcod bench refine [--np N] [--coarse LIST] [--hurst LIST] [--svg FILE]  (--help for more)", &
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
      checks = event_checks(leg)
      call row("self-affine 5 um", 512, inc, "incremental", err, "legacy: first "//int_str(n)// &
         " contacts identical, max rel. load diff. before; legacy took "//int_str(checks%missed_during_run)// &
         " contacts late, its final check found "//int_str(checks%missed_final_check), peak)
      call row("self-affine 5 um", 512, leg, "legacy", err, "incremental, as above", peak_mb())

      allocate(cg_loads(merge(2, 1, full)), cg_approach(merge(2, 1, full)))
      do k = 1, merge(2, 1, full)
         options%max_contacts = 2621*merge(1, 5, k == 1)
         call reset_peak()
         call solve_with("incremental", rough, options, inc)
         checks = event_checks(inc)
         call row("self-affine 5 um, to "//int_str(merge(1, 5, k == 1))//" %", 512, inc, "incremental", &
            max(checks%final_check_difference, checks%max_penetration), "fresh solve of the final active set", peak_mb())
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
         int_str(cg_iterations_in_all(inc))//" iterations in all, residual "// &
         real_str(largest_cg_residual(inc), 2), peak_mb())

      ! Verification decks against their analytic or thesis values.
      if (allocated(options%loads)) deallocate(options%loads)
      options%max_contacts = 0
      call verification_row("circle_punch_d9", 1.0_dp, TABLE_4_1_APPROACH(3), "Table 4.1 approach "// &
         real_str(TABLE_4_1_APPROACH(3), 3)//" nm", options)
      call verification_row("square_punch_n27", 1.0_dp, TABLE_4_2_APPROACH(4), "Table 4.2 approach "// &
         real_str(TABLE_4_2_APPROACH(4), 3)//" nm", options)
      call verification_row("sphere_d05", 18000.0_dp, segedin(18000.0_dp), "Segedin approach at 18000 nN", options)
   end subroutine bench_thesis

   !> Two rows for a verification deck of input/ (built in memory: the bench runs from any
   !> directory) at `load` (nN): the incremental and legacy solvers' approaches against
   !> `reference` (nm), the thesis' or the closed form's, named by `what`.
   subroutine verification_row(name, load, reference, what, options)
      character(len=*), intent(in) :: name, what
      real(dp), intent(in) :: load, reference
      type(contact_options), intent(inout) :: options
      type(scene_spec) :: verification
      type(contact_problem) :: deck
      type(contact_result) :: inc, leg
      type(status_type) :: status
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
      type(contact_problem), intent(inout) :: problem
      type(contact_options), intent(inout) :: opts
      type(contact_result), intent(out) :: res
      type(status_type) :: status
      opts%solver = solver_from_name(solver)
      call solve_contact(problem, opts, res, status)
      if (status%code /= 0) write(error_unit, '(a)') "femcod bench: "//solver//": "//status%message
   end subroutine solve_with

   !> The options of `femcod bench`.
   function bench_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [flag_option("--full", "add the run to 5 % contact (minutes)"), &
         integer_option("--legacy-contacts", "N", "how far the legacy solver runs on the rough surface (default 300)", &
            lower=1)]
   end function bench_table
end module femcod_bench_thesis
