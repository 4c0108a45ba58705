!> `femcod bench tangential`: the tangential step with Coulomb friction (issue 37's second
!> route) by resolution, on rough surfaces, and beside tamaas' PolonskyKeerTan.
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_tangential
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem, paraboloid_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings, SOLVER_CG, BOUNDARY_PERIODIC
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, flag_option, text_option, get_option, &
      option_given
   use femcod_output_guard, only: guard_outputs, OUTPUT_RESULT
   use femcod_scene, only: initial_gap_map
   use femcod_clock, only: wall_clock
   use femcod_svg, only: svg_series, svg_multi_plot, add_series
   use femcod_files, only: write_file
   use femcod_bench_common, only: bench_arguments, require_peers, write_peer_gaps, remove_file_quietly, peer_line, &
      reset_peak, peak_mb
   implicit none
   private
   public :: bench_tangential

   real(dp), parameter :: pi = acos(-1.0_dp)
   !> The rough cells' friction coefficient.
   real(dp), parameter :: mu = 0.3_dp

contains

   function bench_tangential_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [flag_option("--full", "Cattaneo-Mindlin at a/d = 64 too"), &
         text_option("--figure", "FILE", "write the stick fraction against Q/(mu P) as an SVG figure"), &
         flag_option("--force", "replace an existing figure that femcod wrote"), &
         text_option("--peers", "PYTHON", "beside tamaas' PolonskyKeerTan in that Python (app/femcod_peers.py)")]
   end function bench_tangential_table

   !> `femcod bench tangential [--full] [--figure FILE] [--peers PYTHON]`.
   subroutine bench_tangential(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(parsed_options) :: parsed
      character(len=:), allocatable :: python, figure
      type(string_type), allocatable :: inputs(:)
      type(status_type) :: status
      logical :: full
      code = 0
      full = .false.
      if (help_requested(args)) then
         call print_tangential_help()
         return
      end if
      if (.not. bench_arguments(bench_tangential_table(), args, "femcod bench tangential", parsed)) then
         code = 2
         return
      end if
      call get_option(parsed, "--full", full)
      python = ""
      figure = ""
      call get_option(parsed, "--peers", python)
      call get_option(parsed, "--figure", figure)
      call require_peers(python, "tangential", code)
      if (code /= 0) return
      ! The figure's name before any work: femcod's rule for every file it writes.
      if (len(figure) > 0) then
         allocate(inputs(0))
         call guard_outputs([string_type(figure)], inputs, option_given(parsed, "--force"), OUTPUT_RESULT, status)
         if (failed(status, code)) return
      end if
      call mindlin_table(full, code)
      if (code == 0) call stick_table(figure, code)
      if (code == 0) call stiffness_table(code)
      if (code == 0 .and. len(python) > 0) call side_by_side(python, code)
   end subroutine bench_tangential

   subroutine print_tangential_help()
      write(output_unit, '(a)') "usage: femcod bench tangential [--full] [--figure FILE [--force]] [--peers PYTHON]", &
         "1. Cattaneo-Mindlin: a rigid paraboloid (R = 1000 nm) on E = 200 GPa, nu = 0, at Hertz's a = 24 nm,", &
         "   Q = mu P/2 (mu = 0.3), pixels a/8, a/16, a/32 (a/64 with --full): the shift and the stick radius", &
         "   against the closed forms, the order of the shift's error, iterations, wall time.", &
         "2. A self-affine periodic cell (256^2 pixels of 2 nm, Hurst 0.8, rms 1 nm, seed 3, E = 200 GPa,", &
         "   nu = 0.3) at mean pressures 0.25 and 1 GPa: the stick fraction of the contact against", &
         "   Q/(mu P), beside the single sphere's (1 - Q/(mu P))^(2/3) (the figure with --figure FILE).", &
         "3. The same cell at mean pressures 0.05 to 2 GPa: the normal stiffness dP/d(approach) (loads", &
         "   1 % apart) and the tangential one Q/shift at Q = 1e-4 mu P (all sticking), their ratio", &
         "   against Mindlin's 2 (1 - nu)/(2 - nu) for one contact.", &
         "4. With --peers PYTHON: the cell at 128^2 and 256^2 (nu = 0.49999: beta = 0, the problems", &
         "   uncouple in both), 1 GPa, Q = mu P/2, beside tamaas' PolonskyKeerTan (tol 1e-7): time,", &
         "   peak memory, contact and stick fractions, the tractions' difference.", ""
      call print_lines(option_help(bench_tangential_table(), ""))
      write(output_unit, '(a)') "Run it with the release build."
   end subroutine print_tangential_help

   !> Part 1: Cattaneo-Mindlin by resolution.
   subroutine mindlin_table(full, code)
      logical, intent(in) :: full
      integer, intent(inout) :: code
      real(dp), parameter :: radius = 1000, a = 24, young = 200, ratio = 0.5_dp
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp) :: load, shift, stick_radius, pixel, t0, t1, got, previous, c
      integer :: level, levels, np
      type(contact_problem) :: scene
      load = 4*young*a**3/(3*radius)
      shift = 3*mu*load*2/(16*a*young/2)*(1 - (1 - ratio)**(2.0_dp/3))
      stick_radius = a*(1 - ratio)**(1.0_dp/3)
      levels = merge(4, 3, full)
      options = tangential_options([load], ratio*mu*load)
      write(output_unit, '(a)') "Cattaneo-Mindlin (nu = 0, Q = mu P/2): shift "//real_str(shift, 8)// &
         " nm, stick radius "//fixed_str(stick_radius, 4)//" nm", ""
      write(output_unit, '(a)') "| a/d | NP | shift (nm) | error | order | stick radius (nm) | error (pixels) | "// &
         "iterations | wall (s) |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|"
      previous = 0
      do level = 1, levels
         pixel = a/2.0_dp**(level + 2)
         np = 2*nint(1.5_dp*a/pixel) + 1
         call wall_clock(t0)
         scene = paraboloid_problem(np, pixel, radius, young)
         call solve_contact(scene, options, res, status)
         call wall_clock(t1)
         if (failed(status, code)) return
         got = res%states(1)%tangential_shift(1)
         c = sqrt(count(res%states(1)%stick)*pixel**2/pi)
         write(output_unit, '(a)') "| "//int_str(2**(level + 2))//" | "//int_str(np)//" | "//real_str(got, 8)// &
            " | "//real_str(abs(got/shift - 1), 2)//" | "//trim(order_text(previous, abs(got/shift - 1)))//" | "// &
            fixed_str(c, 3)//" | "//fixed_str(abs(c - stick_radius)/pixel, 2)//" | "// &
            int_str(res%states(1)%tangential_iterations)//" | "//fixed_str(t1 - t0, 2)//" |"
         flush(output_unit)
         previous = abs(got/shift - 1)
      end do
   contains
      function order_text(coarser, finer) result(text)
         real(dp), intent(in) :: coarser, finer
         character(len=:), allocatable :: text
         text = ""
         if (coarser > 0 .and. finer > 0) text = fixed_str(log(coarser/finer)/log(2.0_dp), 2)
      end function order_text
   end subroutine mindlin_table

   !> cg options at `loads` (nN) with the tangential step Q (nN) and mu.
   function tangential_options(loads, q) result(options)
      real(dp), intent(in) :: loads(:), q
      type(contact_options) :: options
      options%solver = SOLVER_CG
      options%loads = loads
      options%cg = cg_settings()
      options%cg%tol = 1.0e-10_dp
      options%cg%max_iterations = 5000
      options%tangential = .true.
      options%friction = mu
      options%tangential_load = q
   end function tangential_options

   !> The rough periodic cell of parts 2 to 4 (NP pixels of 2 nm, Poisson's ratio nu).
   subroutine rough_cell(np, nu, deck, code)
      integer, intent(in) :: np
      real(dp), intent(in) :: nu
      type(contact_problem), intent(out) :: deck
      integer, intent(inout) :: code
      type(scene_spec) :: spec
      type(status_type) :: status
      spec%kind = "self-affine"
      spec%np = np
      spec%pixel = 2
      spec%hurst = 0.8_dp
      spec%rms = 1
      spec%seed = 3
      spec%young = 200
      spec%poisson = nu
      spec%shape_on = "lower"
      spec%rigid = "upper"
      spec%label = "bench tangential"
      spec%matrix_file = ""
      spec%maxcont = np**2
      call build_problem(spec, deck, status)
      if (failed(status, code)) return
   end subroutine rough_cell

   !> Part 2: the stick fraction against Q/(mu P) at two mean pressures; the figure.
   subroutine stick_table(figure, code)
      character(len=*), intent(in) :: figure
      integer, intent(inout) :: code
      real(dp), parameter :: pressures(2) = [0.25_dp, 1.0_dp]
      real(dp), parameter :: fractions(10) = [0.05_dp, 0.15_dp, 0.25_dp, 0.35_dp, 0.45_dp, 0.55_dp, 0.65_dp, &
         0.75_dp, 0.85_dp, 0.95_dp]
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      type(svg_series), allocatable :: series(:)
      real(dp) :: stick(size(fractions), size(pressures)), load, curve(101), x(101), t0, t1
      integer :: c, k
      call rough_cell(256, 0.3_dp, deck, code)
      if (code /= 0) return
      write(output_unit, '(a)') "", "Stick fraction of the contact on a rough periodic cell (256^2, 2 nm pixels, "// &
         "nu = 0.3, mu = 0.3)", ""
      write(output_unit, '(a)') "| mean pressure (GPa) | contact % | Q/(mu P) | stick fraction | "// &
         "sphere (1 - Q/(mu P))^(2/3) | shift (nm) | iterations | wall (s) |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|"
      allocate(series(0))
      do c = 1, size(pressures)
         load = pressures(c)*(deck%np*deck%pixel)**2
         do k = 1, size(fractions)
            options = tangential_options([load], fractions(k)*mu*load)
            options%boundary = BOUNDARY_PERIODIC
            call wall_clock(t0)
            call solve_contact(deck, options, res, status)
            call wall_clock(t1)
            if (failed(status, code)) return
            associate(s => res%states(1))
               stick(k, c) = real(count(s%stick), dp)/size(s%stick)
               write(output_unit, '(a)') "| "//fixed_str(pressures(c), 2)//" | "// &
                  fixed_str(100*real(s%contacts, dp)/deck%np**2, 2)//" | "//fixed_str(fractions(k), 2)//" | "// &
                  fixed_str(stick(k, c), 4)//" | "//fixed_str((1 - fractions(k))**(2.0_dp/3), 4)//" | "// &
                  real_str(s%tangential_shift(1), 5)//" | "//int_str(s%tangential_iterations)//" | "// &
                  fixed_str(t1 - t0, 2)//" |"
               flush(output_unit)
            end associate
         end do
         call add_series(series, "rough cell, "//fixed_str(pressures(c), 2)//" GPa", fractions, stick(:, c))
      end do
      if (len(figure) == 0) return
      x = [(k/100.0_dp, k = 0, 100)]
      curve = (1 - x)**(2.0_dp/3)
      call add_series(series, "one sphere (Cattaneo-Mindlin)", x, curve, dashed=.true., markers=.false.)
      call write_file(figure, svg_multi_plot("stick fraction of the contact against the tangential load", &
         "Q / (mu P)", "sticking contact / contact", series, .false., .false.), status)
      if (failed(status, code)) return
      write(output_unit, '(a)') "", "wrote "//figure
   end subroutine stick_table

   !> Part 3: the normal and tangential stiffness of the rough cell against the load.
   subroutine stiffness_table(code)
      integer, intent(inout) :: code
      real(dp), parameter :: pressures(5) = [0.05_dp, 0.1_dp, 0.25_dp, 0.5_dp, 1.0_dp]
      real(dp), parameter :: nu = 0.3_dp, eps = 0.01_dp
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp) :: load, kn, kt, mindlin
      integer :: c
      call rough_cell(256, nu, deck, code)
      if (code /= 0) return
      mindlin = 2*(1 - nu)/(2 - nu)
      write(output_unit, '(a)') "", "Stiffness of the rough cell: normal dP/d(approach) (loads 1 % apart), "// &
         "tangential Q/shift at Q = 1e-4 mu P (all sticking); Mindlin's ratio for one contact "// &
         fixed_str(mindlin, 4), ""
      write(output_unit, '(a)') "| mean pressure (GPa) | contact % | k_n (nN/nm) | k_t (nN/nm) | k_t/k_n | "// &
         "against Mindlin |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|"
      do c = 1, size(pressures)
         load = pressures(c)*(deck%np*deck%pixel)**2
         options = tangential_options([load*(1 - eps/2), load*(1 + eps/2)], 1.0e-4_dp*mu*load*(1 - eps/2))
         options%boundary = BOUNDARY_PERIODIC
         call solve_contact(deck, options, res, status)
         if (failed(status, code)) return
         kn = eps*load/(res%states(2)%approach - res%states(1)%approach)
         kt = res%states(1)%tangential_force(1)/res%states(1)%tangential_shift(1)
         write(output_unit, '(a)') "| "//fixed_str(pressures(c), 2)//" | "// &
            fixed_str(100*real(res%states(1)%contacts, dp)/deck%np**2, 2)//" | "//real_str(kn, 5)//" | "// &
            real_str(kt, 5)//" | "//fixed_str(kt/kn, 4)//" | "//fixed_str(kt/kn/mindlin, 4)//" |"
         flush(output_unit)
      end do
   end subroutine stiffness_table

   !> Part 4: beside tamaas' PolonskyKeerTan on the cell at 128^2 and 256^2.
   subroutine side_by_side(python, code)
      character(len=*), intent(in) :: python
      integer, intent(inout) :: code
      real(dp), parameter :: nu = 0.49999_dp, pressure = 1, tol = 1.0e-7_dp
      character(len=*), parameter :: path = "femcod-bench-tangential.gaps"
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      character(len=512) :: line
      character(len=64) :: words(8)
      real(dp), allocatable :: theirs(:), mine(:, :, :)
      real(dp) :: load, t0, t1, peak
      integer :: c, k, np, unit, ios
      integer, parameter :: sizes(2) = [128, 256]
      write(output_unit, '(a)') "", "Beside tamaas' PolonskyKeerTan (periodic cell, nu = 0.49999, 1 GPa, Q = mu P/2)", ""
      write(output_unit, '(a)') "| NP | solver | seconds | peak MB | contact % | stick % | |tau| difference | "// &
         "p difference |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|"
      do c = 1, size(sizes)
         np = sizes(c)
         call rough_cell(np, nu, deck, code)
         if (code /= 0) return
         load = pressure*(np*deck%pixel)**2
         options = tangential_options([load], 0.5_dp*mu*load)
         options%boundary = BOUNDARY_PERIODIC
         call reset_peak()
         call wall_clock(t0)
         call solve_contact(deck, options, res, status)
         call wall_clock(t1)
         peak = peak_mb()
         if (failed(status, code)) return
         allocate(mine(np, np, 3))
         mine = 0
         associate(s => res%states(1))
            do k = 1, size(s%i)
               mine(s%i(k), s%j(k), :) = [s%shear_x(k), s%shear_y(k), s%force(k)]/deck%pixel**2
            end do
            write(output_unit, '(a)') "| "//int_str(np)//" | femcod | "//fixed_str(t1 - t0, 3)//" | "// &
               int_str(nint(peak))//" | "//fixed_str(100*real(s%contacts, dp)/np**2, 3)//" | "// &
               fixed_str(100*real(count(s%stick), dp)/np**2, 3)//" | | |"
         end associate
         call write_peer_gaps(path, initial_gap_map(deck%lower, deck%upper))
         line = peer_line(python, "tamaas-tangential", path, np, deck%pixel, deck%young(1), pressure, tol, &
            extra=real_str(nu, 6)//" "//real_str(mu, 6)//" 0.5")
         words = "-"
         read(line, *, iostat=ios) words
         allocate(theirs(3*np*np))
         open(newunit=unit, file=path//".tractions", access="stream", form="unformatted", status="old", &
            action="read", iostat=ios)
         if (ios == 0) then
            read(unit, iostat=ios) theirs
            close(unit)
         end if
         if (ios == 0) then
            write(output_unit, '(a)') "| "//int_str(np)//" | tamaas ("//trim(words(7))//") | "//trim(words(2))// &
               " | "//trim(words(6))//" | "//trim(percent(words(5)))//" | "//trim(percent(words(8)))//" | "// &
               real_str(difference(mine(:, :, 1:2), reshape(theirs(1:2*np*np), [np, np, 2])), 2)//" | "// &
               real_str(difference(mine(:, :, 3:3), reshape(theirs(2*np*np + 1:), [np, np, 1])), 2)//" |"
         else
            write(output_unit, '(a)') "| "//int_str(np)//" | tamaas | "//trim(line)//" | | | | | |"
         end if
         flush(output_unit)
         call remove_file_quietly(path)
         call remove_file_quietly(path//".tractions")
         deallocate(theirs, mine)
      end do
   contains
      !> The relative L2 difference of two fields (theirs the reference).
      real(dp) function difference(a, b)
         real(dp), intent(in) :: a(:, :, :), b(:, :, :)
         difference = sqrt(sum((a - b)**2)/sum(b**2))
      end function difference
      function percent(word) result(text)
         character(len=*), intent(in) :: word
         character(len=:), allocatable :: text
         real(dp) :: v
         integer :: ios2
         read(word, *, iostat=ios2) v
         text = trim(word)
         if (ios2 == 0) text = fixed_str(100*v, 3)
      end function percent
   end subroutine side_by_side

   !> Report a failed status (its message on standard error, its code out): true if it failed.
   logical function failed(status, code)
      type(status_type), intent(in) :: status
      integer, intent(inout) :: code
      failed = status%code /= 0
      if (.not. failed) return
      write(error_unit, '(a)') "femcod bench tangential: "//status%message
      code = status%code
   end function failed
end module femcod_bench_tangential
