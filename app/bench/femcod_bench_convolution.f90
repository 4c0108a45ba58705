!> `femcod bench convolution`: the Love-kernel convolution's transforms (double, float32).
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_convolution
   use, intrinsic :: iso_fortran_env, only: output_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, integer_option, integer_list_option, &
      choice_option, get_option
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, &
      convolution_free
   use femcod_love, only: offset_table
   use femcod_love_periodic, only: periodic_offset_table
   use femcod_random, only: random_stream, seed_stream, uniform
   use femcod_clock, only: wall_clock
   use femcod_bench_common, only: bench_arguments, bare_pair_seconds
   implicit none
   private
   public :: bench_convolution

contains

   !> `femcod bench convolution`: one Love convolution on NP x NP (zero-padded (2NP)^2
   !> transforms; with --boundary periodic the cyclic one on NP^2) with FFTW's estimated and
   !> measured plans: set-up time (planning, kernel spectrum), time per convolution in double
   !> and float32 and each against a bare pair (FFTW's threaded 2-D r2c and c2r of the same
   !> transform grid in double, the same plan flags: the limit of one convolution), the
   !> float32 result's largest difference from double, and double's largest difference from
   !> the direct sum sum_k I(p - k) F(k) at three pixels (corner, centre, edge; O(NP^2)
   !> each), all relative to the largest value. The field is uniform random on [0, 1)
   !> (seed 1).
   subroutine bench_convolution(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer, allocatable :: sizes(:)
      real(dp), allocatable :: table(:, :), field(:, :), double(:, :), single(:, :)
      type(love_convolution) :: conv
      type(random_stream) :: stream
      real(dp) :: t0, t1, setup, t_double, t_single, t_pair, err_single, err_direct, direct, scale
      integer :: n, np, repeat, k, plans, probe(2, 3), kk, l
      character(len=:), allocatable :: boundary
      logical :: periodic
      type(parsed_options) :: parsed
      type(status_type) :: status
      sizes = [512, 1024, 2048]
      repeat = 5
      boundary = "free"
      if (help_requested(args)) then
         write(output_unit, '(a)') "usage: femcod bench convolution [--np 512,1024,2048] [--repeat 5] "// &
            "[--boundary free|periodic]", &
            "One Love-kernel convolution on NP x NP by zero-padded (2NP)^2 FFTs (periodic: cyclic on NP^2), with", &
            "FFTW's estimated and measured plans (measured here, no wisdom): set-up time, time per convolution", &
            "in double and float32 (mean of --repeat, after one untimed) and each over a bare pair (FFTW's", &
            "threaded 2-D r2c and c2r of the same grid in double, timed alike: the limit), float32's largest", &
            "difference from double, and double's largest difference from the direct sum at three pixels,", &
            "relative to the largest value.", ""
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
      call get_option(parsed, "--boundary", boundary)
      periodic = boundary == "periodic"
      write(output_unit, '(a)') "| NP | plans | set-up (s) | double (s) | float32 (s) | bare pair (s) "// &
         "| double / pair | float32 / pair | float32 - double | double - direct sum |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|---|"
      do n = 1, size(sizes)
         np = sizes(n)
         allocate(table(0:np - 1, 0:np - 1), field(np, np), double(np, np), single(np, np))
         if (periodic) then
            table = periodic_offset_table(np)
         else
            table = offset_table(np)
         end if
         call seed_stream(stream, 1)
         do l = 1, np
            do k = 1, np
               call uniform(stream, field(k, l))
            end do
         end do
         probe = reshape([1, 1, (np + 1)/2, (np + 1)/2, np, (np + 1)/3], [2, 3])
         do plans = 1, 2
            call wall_clock(t0)
            call convolution_setup(conv, table, single=.true., measure=plans == 2, periodic=periodic)
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
            t_pair = bare_pair_seconds(merge(np, 2*np, periodic), measure=plans == 2, repeat=repeat)
            scale = maxval(abs(double))
            err_single = maxval(abs(single - double))/scale
            err_direct = 0
            do kk = 1, 3
               direct = 0
               do l = 1, np
                  do k = 1, np
                     if (periodic) then
                        direct = direct + table(modulo(probe(1, kk) - k, np), modulo(probe(2, kk) - l, np))*field(k, l)
                     else
                        direct = direct + table(abs(probe(1, kk) - k), abs(probe(2, kk) - l))*field(k, l)
                     end if
                  end do
               end do
               err_direct = max(err_direct, abs(double(probe(1, kk), probe(2, kk)) - direct)/scale)
            end do
            write(output_unit, '(a)') "| "//int_str(np)//" | "//trim(merge("estimated", "measured ", plans == 1))// &
               " | "//fixed_str(setup, 3)//" | "//fixed_str(t_double, 4)//" | "//fixed_str(t_single, 4)//" | "// &
               fixed_str(t_pair, 4)//" | "//fixed_str(t_double/t_pair, 2)//" | "//fixed_str(t_single/t_pair, 2)// &
               " | "//real_str(err_single, 2)//" | "//real_str(err_direct, 2)//" |"
            flush(output_unit)
         end do
         deallocate(table, field, double, single)
      end do
   end subroutine bench_convolution

   !> The options of `femcod bench convolution`.
   function bench_convolution_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_list_option("--np", "N1,...", "grid sizes (default 512,1024,2048)", lower=2), &
         integer_option("--repeat", "N", "convolutions timed per size and precision (default 5)", lower=1), &
         choice_option("--boundary", "free|periodic", "free (default): zero-padded (2NP)^2 transforms; periodic: "// &
            "the cyclic convolution on NP^2")]
   end function bench_convolution_table
end module femcod_bench_convolution
