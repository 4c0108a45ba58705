!> `femcod bench frontier`: speed against error of every solver setting (the frontier).
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_frontier
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem, verification_spec
   use femcod_contact_result, only: contact_result, cg_state_diagnostics, cg_work, cg_iterations_in_all
   use femcod_solver_options, only: contact_options, cg_settings, &
      SOLVER_LEGACY, SOLVER_CG
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_output_guard, only: guard_outputs, OUTPUT_RESULT
   use femcod_options, only: option_spec, parsed_options, option_help, flag_option, real_option, integer_option, &
      text_option, real_list_option, get_option, option_given
   use femcod_scene, only: initial_gaps
   use femcod_clock, only: wall_clock
   use femcod_files, only: write_file, file_part
   use femcod_svg, only: svg_series, add_series, svg_multi_plot
   use femcod_resolution_study, only: level_deck
   use femcod_resolution, only: mccool_surface, mccool_area, mccool_parameters
   use femcod_love, only: love_influence, surface_compliance, composite_modulus
   use femcod_spring, only: spring_stiffness
   use femcod_scene, only: flip_upper
   use femcod_sort, only: merge_sort_index
   use femcod_bench_common, only: bench_arguments, benchmark_surface, linear_law, BENCH_LENGTH
   implicit none
   private
   public :: bench_frontier

   !> The table being made: the case's deck (np x np, its gaps g0, nm), its label, the
   !> rows' times (s) and area errors for the figure, the figure's series, the status of
   !> the last solve.
   type :: frontier_table
      type(contact_problem) :: deck
      integer :: np = 0
      real(dp), allocatable :: g0(:, :), times(:), errors(:)
      character(len=:), allocatable :: case_label
      type(svg_series), allocatable :: series(:)
      type(status_type) :: status
   end type frontier_table

contains

   !> `femcod bench frontier`: every way femcod answers "approach and contact area at
   !> load F" on the benchmark surface, as wall time against the relative error of each
   !> against the event-exact answer at that load (issue 21's frontier, first part).
   subroutine bench_frontier(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer :: np, f
      real(dp), allocatable :: fractions(:)
      character(len=:), allocatable :: svg_path, deck_path
      type(contact_problem) :: thesis
      real(dp) :: deck_load, estar, slope, load
      type(parsed_options) :: parsed
      type(frontier_table) :: tab
      associate(status => tab%status, deck => tab%deck)
      np = 256
      fractions = [1.0_dp, 5.0_dp]
      svg_path = ""
      deck_path = "input/sphere_d1.deck"
      deck_load = 1000
      if (help_requested(args)) then
         call print_frontier_help()
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
      ! The figure's name before any work: femcod's rule for every file it writes.
      if (len(svg_path) > 0) call guard_outputs([string_type(svg_path)], [string_type(deck_path)], &
         option_given(parsed, "--force"), OUTPUT_RESULT, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod bench frontier: "//status%message
         code = status%code
         return
      end if
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
      tab%np = np
      call linear_law(deck, estar, slope, tab%g0)
      write(output_unit, '(a)') "| case | method | wall (s) | approach error | area error | note |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|"
      allocate(tab%series(0))
      do f = 1, size(fractions)
         load = fractions(f)/100*estar*slope/2*BENCH_LENGTH**2
         tab%case_label = fixed_str(fractions(f), 1)//" %"
         call frontier_case(tab, load, .false.)
         if (status%code /= 0) return
      end do
      ! One thesis deck, with the Appendix B program among the methods.
      if (len(deck_path) > 0) then
         deck = thesis
         np = deck%np
         tab%np = np
         tab%g0 = transpose(reshape(initial_gaps(deck%lower, deck%upper), [np, np]))
         tab%case_label = file_part(deck_path)
         call frontier_case(tab, deck_load, .true.)
         if (status%code /= 0) return
      end if
      if (len(svg_path) > 0) then
         call write_file(svg_path, svg_multi_plot("speed against error: approach and area at load F (NP = "// &
            int_str(np)//")", "wall time (s)", "relative error of the contact area", tab%series, .true., .true.), status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench frontier: "//status%message
            code = status%code
         end if
      end if
      end associate
   end subroutine bench_frontier

   !> `femcod bench frontier --help`.
   subroutine print_frontier_help()
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
   end subroutine print_frontier_help

   !> Every method at load F on `deck` (np, g0 its grid and gaps), rows labelled
   !> case_label; with `legacy`, the Appendix B program as well.
   subroutine frontier_case(tab, load, legacy)
      type(frontier_table), intent(inout) :: tab
      real(dp), intent(in) :: load
      logical, intent(in) :: legacy
      real(dp), parameter :: tols(5) = [1.0e-2_dp, 1.0e-4_dp, 1.0e-6_dp, 1.0e-8_dp, 1.0e-10_dp]
      real(dp), parameter :: radii(4) = [28.0_dp, 64.0_dp, 128.0_dp, 283.0_dp]
      character(len=*), parameter :: methods(2) = [character(len=9) :: "average", "subsample"]
      type(contact_options) :: options
      type(contact_result) :: res
      type(contact_problem) :: coarse
      real(dp) :: a_ref, c_ref, t0, t1, approach, area
      integer :: k, m, factor, method
      associate(status => tab%status, deck => tab%deck, np => tab%np, case_label => tab%case_label)
      allocate(tab%times(0), tab%errors(0))
         ! The reference: the event-exact state at F.
         options = contact_options()
         options%loads = [load]
         call timed_solve(tab, deck, options, res, t1)
         if (status%code /= 0) return
         a_ref = res%states(1)%approach
         c_ref = res%states(1)%contacts*deck%pixel**2
         call frontier_row(tab, "event-exact (reference)", t1, 0.0_dp, 0.0_dp, "F = "//real_str(load, 6)//" nN, "// &
            int_str(res%states(1)%contacts)//" contacts")
         ! cg at each tolerance, with and without float32 and the nested start.
         do m = 1, 4
            do k = 1, size(tols)
               options = contact_options()
               options%solver = SOLVER_CG
               options%loads = [load]
               options%cg = cg_settings()
               options%cg%tol = tols(k)
               options%cg%max_iterations = 5000
               if (m == 2 .or. m == 4) options%cg%single_until = 0
               if (m >= 3) options%cg%nested = .false.
               call timed_solve(tab, deck, options, res, t1)
               if (status%code /= 0) then
                  call frontier_row(tab, "cg tol "//real_str(tols(k), 1), -1.0_dp, -1.0_dp, -1.0_dp, status%message)
                  status = status_type()
                  cycle
               end if
               call frontier_row(tab, "cg tol "//real_str(tols(k), 1)//trim(merge(", no float32", "            ", &
                  m == 2 .or. m == 4))//trim(merge(", no nested start", "                 ", m >= 3)), t1, &
                  rel(res%states(1)%approach, a_ref), rel(res%states(1)%contacts*deck%pixel**2, c_ref), &
                  int_str(cg_iterations_in_all(res))//" iterations, approach bound "// &
                  real_str(first_state_bound(res)/abs(a_ref), 2))
            end do
         end do
         ! The Love kernel truncated (the thesis' 28 and 283 pixels, section 5.2.2 iii).
         do k = 1, size(radii)
            options = contact_options()
            options%solver = SOLVER_CG
            options%loads = [load]
            options%cg = cg_settings()
            options%cg%max_iterations = 5000
            options%cg%kernel_radius = radii(k)
            call timed_solve(tab, deck, options, res, t1)
            if (status%code /= 0) then
               call frontier_row(tab, "cg, kernel truncated at "//int_str(nint(radii(k)))//" pixels", -1.0_dp, -1.0_dp, &
                  -1.0_dp, status%message)
               status = status_type()
               cycle
            end if
            call frontier_row(tab, "cg, kernel truncated at "//int_str(nint(radii(k)))//" pixels", t1, &
               rel(res%states(1)%approach, a_ref), rel(res%states(1)%contacts*deck%pixel**2, c_ref), &
               int_str(cg_iterations_in_all(res))//" iterations, tol 1e-8")
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
                  call frontier_row(tab, "down-sampled 1/"//int_str(factor)//", "//trim(methods(method)), -1.0_dp, &
                     -1.0_dp, -1.0_dp, "not reached: "//status%message)
                  status = status_type()
               else
                  call frontier_row(tab, "down-sampled 1/"//int_str(factor)//", "//trim(methods(method)), t1 - t0, &
                     rel(res%states(1)%approach, a_ref), rel(res%states(1)%contacts*coarse%pixel**2, c_ref), &
                     int_str(np/factor)//"^2 pixels")
               end if
               factor = 2*factor
            end do
         end do
         ! The uncoupled voxels: the approach where their load is F, by bisection.
         call wall_clock(t0)
         call uncoupled_at(tab, load, approach, area)
         call wall_clock(t1)
         call frontier_row(tab, "uncoupled voxels", t1 - t0, rel(approach, a_ref), rel(area, c_ref), &
            "single-pixel compliance, no coupling")
         ! McCool's Greenwood-Williamson model: the area at the nominal pressure.
         call wall_clock(t0)
         call mccool_at(tab, load, area)
         call wall_clock(t1)
         call frontier_row(tab, "McCool (Greenwood-Williamson)", t1 - t0, -1.0_dp, rel(area, c_ref), "area only")
         if (legacy) then
            options = contact_options()
            options%solver = SOLVER_LEGACY
            options%loads = [load]
            call timed_solve(tab, deck, options, res, t1)
            if (status%code /= 0) then
               call frontier_row(tab, "legacy (Appendix B)", -1.0_dp, -1.0_dp, -1.0_dp, status%message)
               status = status_type()
            else
               call frontier_row(tab, "legacy (Appendix B)", t1, rel(res%states(1)%approach, a_ref), &
                  rel(res%states(1)%contacts*deck%pixel**2, c_ref), int_str(res%nsteps)//" steps")
            end if
         end if
         call add_series(tab%series, case_label, tab%times, tab%errors, dashed=.true.)
         call add_series(tab%series, "Pareto front, "//case_label, pack(tab%times, front(tab%times, tab%errors)), &
            pack(tab%errors, front(tab%times, tab%errors)), markers=.false.)
         deallocate(tab%times, tab%errors)
      end associate
   end subroutine frontier_case

   pure real(dp) function rel(x, reference)
      real(dp), intent(in) :: x, reference
      rel = abs(x - reference)/abs(reference)
   end function rel

   !> One solve, timed (s); a failure stays in tab%status.
   subroutine timed_solve(tab, problem, opts, out, seconds)
      type(frontier_table), intent(inout) :: tab
      type(contact_problem), intent(inout) :: problem
      type(contact_options), intent(in) :: opts
      type(contact_result), intent(out) :: out
      real(dp), intent(out) :: seconds
      real(dp) :: s0, s1
      call wall_clock(s0)
      call solve_contact(problem, opts, out, tab%status)
      call wall_clock(s1)
      seconds = s1 - s0
   end subroutine timed_solve

   !> A row of the table; a time below 0: failed; an error below 0: not estimated.
   !> Points with an area error go on the figure (an error of 0, the reference, at
   !> 1e-16: the figure is logarithmic).
   subroutine frontier_row(tab, name, seconds, approach_error, area_error, note)
      type(frontier_table), intent(inout) :: tab
      character(len=*), intent(in) :: name, note
      real(dp), intent(in) :: seconds, approach_error, area_error
      character(len=:), allocatable :: ta, tc
      ta = "-"
      tc = "-"
      if (approach_error >= 0) ta = real_str(approach_error, 2)
      if (area_error >= 0) tc = real_str(area_error, 2)
      if (seconds < 0) then
         write(output_unit, '(a)') "| "//tab%case_label//" | "//name//" | failed | | | "//note//" |"
      else
         write(output_unit, '(a)') "| "//tab%case_label//" | "//name//" | "//real_str(seconds, 3)// &
            " | "//ta//" | "//tc//" | "//note//" |"
         if (area_error >= 0) then
            tab%times = [tab%times, max(seconds, 1.0e-6_dp)]
            tab%errors = [tab%errors, max(area_error, 1.0e-16_dp)]
         end if
      end if
      flush(output_unit)
   end subroutine frontier_row

   !> The points no other point beats in both time and error.
   pure function front(t, e) result(keep)
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
   subroutine uncoupled_at(tab, target, d, a)
      type(frontier_table), intent(in) :: tab
      real(dp), intent(in) :: target
      real(dp), intent(out) :: d, a
      real(dp) :: cself, partial
      real(dp), allocatable :: gaps(:)
      integer, allocatable :: order(:)
      integer :: k
      gaps = reshape(tab%g0, [tab%np*tab%np])
      allocate(order(size(gaps)))
      call merge_sort_index(gaps, order)
      gaps = gaps(order)
      associate(deck => tab%deck)
         cself = (surface_compliance(deck%young(1), deck%poisson(1), deck%pixel) + &
            surface_compliance(deck%young(2), deck%poisson(2), deck%pixel))*love_influence(0, 0) + &
            3/spring_stiffness(deck%young(3), deck%poisson(3), deck%pixel, deck%pixel)
      end associate
      partial = 0
      do k = 1, size(gaps)
         partial = partial + gaps(k)
         ! Load at the next gap with k pixels carrying: (k g_{k+1} - S_k)/c.
         if (k == size(gaps)) exit
         if ((k*gaps(k + 1) - partial)/cself >= target) exit
      end do
      d = (cself*target + partial)/k
      a = k*tab%deck%pixel**2
   end subroutine uncoupled_at

   !> McCool's area at the nominal pressure F / (NP d)^2, on the composite roughness.
   subroutine mccool_at(tab, target, a)
      type(frontier_table), intent(in) :: tab
      real(dp), intent(in) :: target
      real(dp), intent(out) :: a
      type(mccool_parameters) :: mc
      real(dp) :: ar(1), nominal
      nominal = (tab%np*tab%deck%pixel)**2
      mc = mccool_surface(tab%deck%lower + flip_upper(tab%deck%upper), tab%deck%pixel)
      call mccool_area(mc, composite_modulus(tab%deck%young(1:2), tab%deck%poisson(1:2)), nominal, [target/nominal], &
         ar)
      a = ar(1)
   end subroutine mccool_at

   function bench_frontier_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_option("--np", "N", "pixels per side of the benchmark surface (default 256)", lower=16), &
         real_list_option("--contact", "F1,...", "contact fractions in percent (default 1,5)", lower=0.0_dp), &
         text_option("--svg", "FILE", "write the figure (log time against log area error, Pareto front)"), &
         flag_option("--force", "replace an existing figure that femcod wrote"), &
         text_option("--deck", "FILE", "a thesis deck solved the same ways, the Appendix B program too (default "// &
            "input/sphere_d1.deck, built in: the bench runs from any directory)"), &
         flag_option("--no-deck", "the benchmark surface only (no thesis deck, no Appendix B program)"), &
         real_option("--deck-load", "F", "the deck's load in nN (default 1000)", lower=0.0_dp, closed="()")]
   end function bench_frontier_table

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
   !> The cg solver's error bound of the first state's approach (nm; -1: none).
   real(dp) function first_state_bound(res) result(bound)
      type(contact_result), intent(in) :: res
      type(cg_state_diagnostics) :: work
      work = cg_work(res, 1)
      bound = work%approach_bound
   end function first_state_bound

end module femcod_bench_frontier
