!> `femcod bench refine`: the thesis' third model (femcod refine) against the one ground
!> truth there is, the same surface solved at full resolution. Self-affine surfaces are
!> made at NP^2 and solved there (cg, periodic) at loads giving about 1, 3 and 10 %
!> contact; the same surfaces averaged to coarser grids (as an AFM tip averages) are
!> solved and refined down to the full-resolution pixel. The table gives each method's
!> area error against the full-resolution answer, and the cost against the full solve.
!> Benchmarks only measure: the model is in src/studies/femcod_refine.
module femcod_bench_refine
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_surfaces, only: self_affine_surface, block_average
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, SOLVER_CG, BOUNDARY_PERIODIC
   use femcod_solver, only: solve_contact
   use femcod_refine_study, only: refine_answer, refine_contact
   use femcod_love, only: composite_modulus
   use femcod_strings, only: string_type, int_str, fixed_str, sig_str
   use femcod_help, only: help_requested
   use femcod_options, only: option_spec, parsed_options, integer_option, real_list_option, integer_list_option, &
      text_option, real_option, get_option
   use femcod_clock, only: wall_clock
   use femcod_files, only: write_file
   use femcod_svg, only: svg_series, add_series, svg_multi_plot
   use femcod_bench_common, only: bench_arguments
   implicit none
   private
   public :: bench_refine

contains

   function bench_refine_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [ &
         integer_option("--np", "N", "the full-resolution grid (default 2048)", lower=64), &
         integer_list_option("--coarse", "N1,...", "the coarse grids, each dividing --np (default 512,256)", lower=16), &
         real_list_option("--hurst", "H1,...", "Hurst exponents (default 0.5,0.7,0.9)", lower=0.0_dp, upper=1.0_dp, &
            closed="()"), &
         real_list_option("--contact", "F1,...", "about these contact fractions (default 0.01,0.03,0.1)", &
            lower=0.0_dp, upper=1.0_dp, closed="()"), &
         integer_option("--seed", "S", "the surfaces' random seed (default 1)", lower=1), &
         real_option("--cutoff", "L", "no roughness below the wavelength L (nm, above 2; default none: "// &
            "self-affine down to the pixel)", lower=2.0_dp, closed="()"), &
         text_option("--svg", "FILE", "write the figure: area against magnification, one case")]
   end function bench_refine_table

   subroutine bench_refine(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(parsed_options) :: parsed
      integer :: np, h, c, k, seed, tally(4)
      integer, allocatable :: coarse(:)
      real(dp), allocatable :: hursts(:), fractions(:), z(:, :), truth(:)
      real(dp) :: fine_seconds, t0, t1, pixel, cutoff
      character(len=:), allocatable :: svg_path, rolloff
      type(contact_problem) :: fine
      type(contact_result) :: res
      type(status_type) :: status
      type(refine_answer) :: answer
      type(svg_series), allocatable :: series(:)
      code = 0
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod bench refine [--np 2048] [--coarse 512,256] [--hurst 0.5,0.7,0.9]", &
            "                          [--contact 0.01,0.03,0.1] [--seed 1] [--cutoff L] [--svg FILE]", &
            "The refinement below the pixel (femcod refine) against full-resolution solves (doc/studies.md)."
         return
      end if
      if (.not. bench_arguments(bench_refine_table(), args, "femcod bench refine", parsed)) then
         code = 2
         return
      end if
      np = 2048
      coarse = [512, 256]
      hursts = [0.5_dp, 0.7_dp, 0.9_dp]
      fractions = [0.01_dp, 0.03_dp, 0.1_dp]
      svg_path = ""
      seed = 1
      call get_option(parsed, "--seed", seed)
      call get_option(parsed, "--np", np)
      call get_option(parsed, "--coarse", coarse)
      call get_option(parsed, "--hurst", hursts)
      call get_option(parsed, "--contact", fractions)
      call get_option(parsed, "--svg", svg_path)
      cutoff = 0  ! none: self_affine_surface cuts only above 2 pixels
      call get_option(parsed, "--cutoff", cutoff)
      if (any(modulo(np, coarse) /= 0) .or. any(coarse >= np)) then
         write(error_unit, '(a)') "femcod bench refine: every --coarse grid must divide --np and be smaller"
         code = 2
         return
      end if
      pixel = 1
      rolloff = ""
      if (cutoff > 0) rolloff = ", no roughness below "//fixed_str(cutoff, 1)//" nm"
      write(output_unit, '(a)') "femcod bench refine: self-affine surfaces (rms 3 nm, seed "//int_str(seed)// &
         rolloff//"), "//int_str(np)//"^2 "// &
         "pixels of "//fixed_str(pixel, 1)//" nm, periodic, E* = 213.3 GPa; the truth: cg at "//int_str(np)//"^2; "// &
         "each method's area fraction error against it (signed, relative), refined down to "//fixed_str(pixel, 1)//" nm"
      write(output_unit, '(a)') "| H | load (nN) | truth | coarse NP | solve | Richardson | Persson | refined "// &
         "(sqrt 2) | refined (kappa) | its band | kappa: 2d-d, 4d-2d, 4d-d, the band's | cost / full solve |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|---|---|---|"
      tally = 0
      allocate(series(0))
      do h = 1, size(hursts)
         allocate(z(np, np))
         call self_affine_surface(np, pixel, hursts(h), 3.0_dp, seed, z, cutoff)
         fine = periodic_problem(z, pixel)
         deallocate(z)
         call wall_clock(t0)
         call solve_contact(fine, options_at(loads_for(fine, fractions)), res, status)
         call wall_clock(t1)
         if (status%code /= 0) exit
         fine_seconds = t1 - t0
         truth = [(real(res%states(k)%contacts, dp)/real(np, dp)**2, k = 1, size(fractions))]
         do c = 1, size(coarse)
            call refine_contact(periodic_problem(block_average(fine%lower, np/coarse(c)), pixel*np/coarse(c)), &
               options_at(loads_for(fine, fractions)), pixel, answer, status)
            if (status%code /= 0) exit
            call print_rows(hursts(h), coarse(c), truth, answer, fine_seconds, tally)
            if (h == 1 .and. c == 1 .and. svg_path /= "") call figure_series(series, answer, truth)
         end do
         if (status%code /= 0) exit
      end do
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod bench refine: "//status%message
         code = status%code
         return
      end if
      write(output_unit, '(a)') "Of "//int_str(tally(1))//" points: the refinement within 10 % at "// &
         int_str(tally(2))//", nearer than Richardson at "//int_str(tally(3))//", the truth inside its band at "// &
         int_str(tally(4))//"."
      if (svg_path /= "") then
         call write_file(svg_path, svg_multi_plot("femcod refine: H = "//fixed_str(hursts(1), 1)//", "// &
            int_str(coarse(1))//"^2 refined to the "//int_str(np)//"^2 pixel, about "// &
            int_str(nint(100*fractions((size(fractions) + 1)/2)))//" % contact", "magnification (coarse pixel / length)", &
            "real area fraction", series, .true., .true.), status)
         if (status%code /= 0) code = status%code
      end if
   end subroutine bench_refine

   function periodic_problem(z, pixel) result(p)
      real(dp), intent(in) :: z(:, :), pixel
      type(contact_problem) :: p
      p%label = "bench refine"
      p%np = size(z, 1)
      p%pixel = pixel
      p%maxcont = p%np**2
      p%young = [200.0_dp, 2.0e12_dp, 2.0e12_dp]
      p%poisson = 0.25_dp
      p%lower = z
      allocate(p%upper(p%np, p%np))
      p%upper = 0
   end function periodic_problem

   function options_at(loads) result(o)
      real(dp), intent(in) :: loads(:)
      type(contact_options) :: o
      o%solver = SOLVER_CG
      o%boundary = BOUNDARY_PERIODIC
      o%loads = loads
      allocate(o%approaches(0))
   end function options_at

   !> Loads for about these contact fractions: f E* h'rms / 2 over the cell (central
   !> differences on the full-resolution surface).
   function loads_for(p, fractions) result(loads)
      type(contact_problem), intent(in) :: p
      real(dp), intent(in) :: fractions(:)
      real(dp) :: loads(size(fractions)), slope2
      slope2 = sum(((cshift(p%lower, 1, 1) - cshift(p%lower, -1, 1))/(2*p%pixel))**2 + &
         ((cshift(p%lower, 1, 2) - cshift(p%lower, -1, 2))/(2*p%pixel))**2)/size(p%lower)
      loads = real(nint(fractions*composite_modulus(p%young(1:2), p%poisson(1:2))*sqrt(slope2)/2*(p%np*p%pixel)**2/100)*100, dp)
   end function loads_for

   !> The table's rows of one coarse grid; tally counts the points, those within 10 %, those
   !> nearer than Richardson (a Richardson without an answer counts as farther) and those
   !> whose truth lies inside the band.
   subroutine print_rows(hurst, np, truth, answer, fine_seconds, tally)
      real(dp), intent(in) :: hurst, truth(:), fine_seconds
      integer, intent(in) :: np
      type(refine_answer), intent(in) :: answer
      integer, intent(inout) :: tally(4)
      integer :: k, last
      real(dp) :: cost, err
      last = size(answer%zeta)
      cost = (answer%solve_seconds + answer%richardson_seconds + answer%refine_seconds)/fine_seconds
      do k = 1, size(truth)
         write(output_unit, '(a)') "| "//fixed_str(hurst, 1)//" | "//sig_str(answer%loads(k), 4)//" | "// &
            fixed_str(truth(k), 5)//" | "//int_str(np)//" | "//signed(answer%coarse(1, k)/truth(k) - 1)//" | "// &
            signed(answer%richardson(last, k)/truth(k) - 1)//" | "//signed(answer%persson(last, k)/truth(k) - 1)// &
            " | "//signed(answer%theory(last, k)/truth(k) - 1)//" | "//signed(answer%refined(last, k)/truth(k) - 1)// &
            " | "//signed(answer%refined_low(last, k)/truth(k) - 1)//" to "// &
            signed(answer%refined_high(last, k)/truth(k) - 1)//" | "//fixed_str(answer%kappa(k), 2)//", "// &
            fixed_str(answer%kappa_coarse, 2)//", "// &
            fixed_str(answer%kappa_two, 2)//", "//fixed_str(answer%band(last), 2)//" | "//sig_str(cost, 3)//" |"
         err = abs(answer%refined(last, k)/truth(k) - 1)
         tally(1) = tally(1) + 1
         if (err <= 0.1_dp) tally(2) = tally(2) + 1
         if (.not. (abs(answer%richardson(last, k)/truth(k) - 1) <= err)) tally(3) = tally(3) + 1
         if (answer%refined_low(last, k) <= truth(k) .and. truth(k) <= answer%refined_high(last, k)) &
            tally(4) = tally(4) + 1
      end do
   end subroutine print_rows

   function signed(x) result(t)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: t
      if (x /= x) then
         t = "-"
      else if (x >= 0) then
         t = "+"//fixed_str(100*x, 1)//" %"
      else
         t = fixed_str(100*x, 1)//" %"
      end if
   end function signed

   !> The figure's curves: every method at the middle load, and the truth at the fine pixel.
   subroutine figure_series(series, answer, truth)
      type(svg_series), allocatable, intent(inout) :: series(:)
      type(refine_answer), intent(in) :: answer
      real(dp), intent(in) :: truth(:)
      integer :: k, last
      last = size(answer%zeta)
      k = (size(truth) + 1)/2
      call add_series(series, "refined (kappa "//fixed_str(answer%kappa(k), 2)//")", answer%zeta, answer%refined(:, k))
      call add_series(series, "refined (sqrt 2)", answer%zeta, answer%theory(:, k))
      call add_series(series, "Persson", answer%zeta, answer%persson(:, k), dashed=.true., markers=.false.)
      if (all(answer%richardson(:, k) == answer%richardson(:, k))) call add_series(series, "Richardson", &
         answer%zeta, answer%richardson(:, k), dashed=.true., markers=.false.)
      call add_series(series, "the coarse solve", [answer%zeta(1), answer%zeta(last)], &
         [answer%coarse(1, k), answer%coarse(1, k)], dashed=.true., markers=.false.)
      call add_series(series, "full-resolution solve", [answer%zeta(last)], [truth(k)])
   end subroutine figure_series
end module femcod_bench_refine
