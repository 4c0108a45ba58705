!> `femcod bench periodic`: the periodic cell against the periodic peers.
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_periodic
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: RIGID_FACTOR
   use femcod_contact_result, only: contact_result, cg_state_diagnostics, cg_work, cg_iterations_in_all
   use femcod_solver_options, only: contact_options, cg_settings, &
      SOLVER_CG, BOUNDARY_PERIODIC, boundary_from_name
   use femcod_solver, only: solve_contact
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, real_option, text_option, real_list_option, &
      integer_list_option, get_option
   use femcod_love_periodic, only: periodic_love_spectrum
   use femcod_bench_common, only: bench_arguments, surface_for_peers, require_peers, &
      remove_file_quietly, peer_line, reset_peak, peak_mb, BENCH_LENGTH, options_refused
   implicit none
   private
   public :: bench_periodic

contains

   !> `femcod bench periodic`: the periodic boundary against Westergaard's sinusoid at 64
   !> to 1024 pixels per period (the discretisation error and its order), and the cost of
   !> the periodic cg solver against the free one on the benchmark surface.
   subroutine bench_periodic(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      real(dp), parameter :: pi = acos(-1.0_dp), widths(3) = [1.0_dp/6, 1.0_dp/4, 1.0_dp/3]
      integer, allocatable :: sizes(:), rough_sizes(:)
      real(dp), allocatable :: fractions(:), z(:, :), s(:, :), previous(:)
      type(contact_problem) :: deck
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: res
      type(parsed_options) :: parsed
      real(dp) :: estar, pstar, lambda, ratio, closed
      real(dp), allocatable :: approach_error(:)
      real(dp) :: tol
      character(len=:), allocatable :: python
      integer :: n, np, j, k, width, i
      sizes = [64, 128, 256, 512, 1024]
      rough_sizes = [512, 1024]
      fractions = [1.0_dp, 10.0_dp, 30.0_dp]
      tol = 1.0e-8_dp
      python = ""
      if (help_requested(args)) then
         call print_periodic_help()
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
      options%solver = SOLVER_CG
      options%boundary = BOUNDARY_PERIODIC
      options%cg = cg_settings()
      options%cg%tol = tol
      if (options_refused(options, "femcod bench periodic")) then
         code = 2
         return
      end if
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
               order_text(previous(k), approach_error(k))//" | "//real_str(np/s(1, 0) - 1, 3)//" | "// &
               fixed_str(res%wall_seconds, 2)//" |"
         end do
         previous = approach_error
         flush(output_unit)
         deallocate(z, s)
      end do
      call rough_table(rough_sizes, fractions, tol, python, code)
   end subroutine bench_periodic

   !> The rough half of the table: the benchmark surface at each NP of `sizes` and each
   !> contact fraction (percent), free and periodic, and the peers (`python`) on it.
   subroutine rough_table(sizes, fractions, tol, python, code)
      integer, intent(in) :: sizes(:)
      real(dp), intent(in) :: fractions(:), tol
      character(len=*), intent(in) :: python
      integer, intent(inout) :: code
      character(len=*), parameter :: boundaries(2) = [character(len=8) :: "free", "periodic"]
      character(len=*), parameter :: peers(2) = [character(len=25) :: "tamaas", "contactmechanics-periodic"]
      type(contact_problem) :: deck
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: res
      real(dp) :: estar, slope, load, peak, pressure, fraction
      character(len=:), allocatable :: path
      character(len=512) :: line
      character(len=64) :: words(8)
      integer :: n, np, k, b, i, ios
      options%solver = SOLVER_CG
      write(output_unit, '(a)') "", "| NP | target % | solver | boundary | wall (s) | iterations | contact % | "// &
         "mean gap (nm) | peak RSS (MB) |", "|---|---|---|---|---|---|---|---|---|"
      do n = 1, size(sizes)
         np = sizes(n)
         call surface_for_peers(np, "bench periodic", python, deck, estar, slope, path, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench periodic: "//status%message
            code = status%code
            return
         end if
         do k = 1, size(fractions)
            pressure = fractions(k)/100*estar*slope/2
            load = pressure*BENCH_LENGTH**2
            do b = 1, size(boundaries)
               options%boundary = boundary_from_name(boundaries(b))
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
                  int_str(cg_iterations_in_all(res))//" (+"//int_str(first_state_coarse(res))//" coarse) | "// &
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
   end subroutine rough_table

   !> `femcod bench periodic --help`.
   subroutine print_periodic_help()
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
   end subroutine print_periodic_help

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
   !> The observed order of convergence between two halvings of the width's error,
   !> log2(previous/now), or "-" where it is not defined (the first size, a zero error).
   function order_text(previous, now) result(text)
      real(dp), intent(in) :: previous, now
      character(len=:), allocatable :: text
      if (previous > 0 .and. now > 0) then
         text = fixed_str(log(previous/now)/log(2.0_dp), 2)
      else
         text = "-"
      end if
   end function order_text
   !> The cg solver's iterations on the coarser grids at the first state.
   integer function first_state_coarse(res) result(n)
      type(contact_result), intent(in) :: res
      type(cg_state_diagnostics) :: work
      work = cg_work(res, 1)
      n = work%coarse_iterations
   end function first_state_coarse

end module femcod_bench_periodic
