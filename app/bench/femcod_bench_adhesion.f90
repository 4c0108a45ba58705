!> `femcod bench adhesion`: the adhesive interface against tamaas' functional.
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_adhesion
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem, paraboloid_problem
   use femcod_contact_result, only: contact_result, cg_iterations_in_all
   use femcod_solver_options, only: contact_options, cg_settings, &
      SOLVER_CG, BOUNDARY_PERIODIC, LAW_DUGDALE, LAW_EXPONENTIAL, law_from_name
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, flag_option, text_option, get_option
   use femcod_analytic, only: maugis_pull_off
   use femcod_scene, only: initial_gaps
   use femcod_clock, only: wall_clock
   use femcod_resolution_study, only: level_deck
   use femcod_gap_cg, only: pixel_stiffness_ratio
   use femcod_bench_common, only: bench_arguments, require_peers, write_peer_gaps, remove_file_quietly, peer_line
   implicit none
   private
   public :: bench_adhesion

   real(dp), parameter :: pi = acos(-1.0_dp)
   !> The spheres' composite modulus E* (GPa).
   real(dp), parameter :: young = 1

contains

   !> `femcod bench adhesion`: the adhesive solver's resolution study (issue 20's checks).
   !> 1. The Maugis-Dugdale sphere: the least load over an unloading path against the
   !>    theory's pull-off (analytic/maugis_minimum) at lambda = 0.1, 1, 2, pixels halved,
   !>    with the first-order extrapolation of each pair. 2. The Contact Mechanics
   !>    Challenge's interaction (E* = 25 MPa, W = 0.05 J/m^2, exponential range 2.071 nm)
   !>    on a self-affine surface at 250 kPa, pixels of 4, 2, 1 nm (2 x 2 averages).
   subroutine bench_adhesion(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(parsed_options) :: parsed
      type(contact_problem) :: fine
      character(len=:), allocatable :: python
      logical :: full
      code = 0
      full = .false.
      if (help_requested(args)) then
         call print_adhesion_help()
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
      call maugis_table(full, code)
      if (code == 0) call challenge_table(full, fine, code)
      if (code == 0 .and. len(python) > 0) call side_by_side(python, fine, code)
   end subroutine bench_adhesion

   !> `femcod bench adhesion --help`.
   subroutine print_adhesion_help()
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
   end subroutine print_adhesion_help

   !> Part 1: the Maugis-Dugdale sphere, the least load along the unloading path against
   !> Maugis' closed form, at pixels 2, 1, 0.5 nm (and 0.25 with `full`).
   subroutine maugis_table(full, code)
      logical, intent(in) :: full
      integer, intent(inout) :: code
      real(dp), parameter :: work = 0.01_dp
      real(dp), parameter :: lambdas(3) = [0.1_dp, 1.0_dp, 2.0_dp], radii(3) = [100.0_dp, 1000.0_dp, 1000.0_dp], &
         boxes(3) = [64.0_dp, 128.0_dp, 128.0_dp]
      type(status_type) :: status
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      real(dp), allocatable :: pixels(:), path(:)
      real(dp) :: theory, pmin, previous, t0, t1, radius
      integer :: c, k, np
      options%solver = SOLVER_CG
      options%adhesion = LAW_DUGDALE
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
                  int_str(cg_iterations_in_all(res))//" | "//fixed_str(t1 - t0, 2)//" |"
            else
               write(output_unit, '(a)') "| "//fixed_str(lambdas(c), 1)//" | "//int_str(nint(radius))//" | "// &
                  fixed_str(pixels(k), 2)//" | "//int_str(np)//" | "//fixed_str(pmin, 4)//" | "// &
                  fixed_str(theory, 4)//" | "//real_str(abs(pmin/theory - 1), 2)//" | "// &
                  fixed_str(2*pmin - previous, 4)//" | "//real_str(abs((2*pmin - previous)/theory - 1), 2)//" | "// &
                  int_str(cg_iterations_in_all(res))//" | "//fixed_str(t1 - t0, 2)//" |"
            end if
            previous = pmin
         end do
      end do
   end subroutine maugis_table

   !> Part 2: the Contact Mechanics Challenge's interaction on a self-affine surface and
   !> its 2 x 2 averages; `fine` (out) the finest surface, for part 3.
   subroutine challenge_table(full, fine, code)
      logical, intent(in) :: full
      type(contact_problem), intent(out) :: fine
      integer, intent(inout) :: code
      type(status_type) :: status
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(scene_spec) :: spec
      real(dp), allocatable :: path(:)
      real(dp) :: t0, t1, target, w, limit
      integer :: k, n, i, j, cmc_np
      options%solver = SOLVER_CG
      options%cg = cg_settings()
      options%cg%max_iterations = 20000
      allocate(options%loads(0))
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
      options%adhesion = LAW_EXPONENTIAL
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
               fixed_str(pixel_stiffness_ratio(deck, options%work, options%range), 2)//" | "// &
               fixed_str(a%approach + w*(b%approach - a%approach), 2)//" | "// &
               fixed_str(100*(a%contacts + w*(b%contacts - a%contacts))/real(deck%np, dp)**2, 2)//" | "// &
               fixed_str(100*(a%attractive + w*(b%attractive - a%attractive))/real(deck%np, dp)**2, 2)//" | "// &
               fixed_str(a%mean_gap + w*(b%mean_gap - a%mean_gap), 2)//" | "//int_str(i)//" | "// &
               int_str(cg_iterations_in_all(res))//" | "//fixed_str(t1 - t0, 2)//" |"
         end associate
         n = n/2
         if (n < 64) exit
      end do
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod bench adhesion: "//status%message
         code = status%code
         return
      end if
   end subroutine challenge_table

   !> Part 3: femcod and tamaas on the periodic sphere at the same mean gaps.
   subroutine side_by_side(python, fine, code)
      character(len=*), intent(in) :: python
      type(contact_problem), intent(inout) :: fine
      integer, intent(inout) :: code
      type(status_type) :: status
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      real(dp) :: t0, t1, w, theory
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
         options%solver = SOLVER_CG
         options%boundary = BOUNDARY_PERIODIC
         allocate(options%loads(0))
         options%adhesion = law_from_name(laws(iw))
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
         options%solver = SOLVER_CG
         options%boundary = BOUNDARY_PERIODIC
         allocate(options%loads(0))
         options%adhesion = LAW_EXPONENTIAL
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

   function bench_adhesion_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [flag_option("--full", "add the 0.25 nm sphere grids and the 512^2 rough grid (minutes more)"), &
         text_option("--peers", "PYTHON", "a Python with tamaas installed: part 3, tamaas beside femcod")]
   end function bench_adhesion_table
end module femcod_bench_adhesion
