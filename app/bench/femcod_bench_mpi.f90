!> `femcod bench mpi`: the whole `femcod-mpi` command on ranks, and the scaling estimate.
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_mpi
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, real_option, integer_option, text_option, &
      integer_list_option, get_option
   use femcod_clock, only: wall_clock
   use femcod_hdf5, only: h5_file, h5_close, h5_create, h5_write, h5_attribute
   use femcod_output_guard, only: OUTPUT_RESULT
   use femcod_about, only: FEMCOD_VERSION
   use femcod_bench_common, only: require_program, prepare_directory, guard_bench_files, &
      bench_arguments, benchmark_surface, linear_law, self_path, json_value, &
      read_text_file, BENCH_LENGTH
   implicit none
   private
   public :: bench_mpi

contains

   !> `femcod bench mpi`: the whole femcod-mpi command under mpirun, as a user runs it,
   !> against the whole serial `femcod run --solver cg`, on the benchmark surface (for the
   !> serial run written once per NP as an HDF5 height file, femcod-mpi makes it on its
   !> ranks with --generate) at the load of about --contact % contact: wall
   !> time, the solve and its shares in transforms and communication (rank 0, from the
   !> run's PREFIX.summary.json), iterations, peak memory of the largest rank, and the
   !> approach's difference from the serial run's.
   subroutine bench_mpi(args, code)
      use omp_lib, only: omp_get_num_procs
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      integer, allocatable :: sizes(:), ranks(:)
      character(len=:), allocatable :: dir, heights, prefix, command, text, mpirun, program, common, generated
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
      ! MB of its input (the surface made on the rank) and its input seconds (making the
      ! surface and the grid); of the largest run on more ranks its communication seconds
      ! and ranks.
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
         call print_mpi_help()
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
      allocate(measured(10, size(sizes)))
      measured = 0
      cores = omp_get_num_procs()
      call check_before_work(sizes, dir, mpirun, program, code)
      if (code /= 0) return
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
         call h5_attribute(file, "/", "femcod_version", FEMCOD_VERSION, status)
         call h5_close(file, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod bench mpi: "//status%message
            code = status%code
            return
         end if
         common = " --loads "//real_str(load, 17)//" --tol "//real_str(tol, 3)//" --force --quiet"
         ! The serial run reads the surface from its HDF5 height file; femcod-mpi makes the
         ! same surface on its ranks (--generate: benchmark_surface's spec), no input file.
         generated = " --generate self-affine --np "//int_str(np)//" --pixel "//real_str(deck%pixel, 17)// &
            " --hurst 0.8 --rms 3 --seed 1 --shape-on lower --rigid upper"
         deallocate(deck%lower, deck%upper)
         ! The serial command on all cores.
         prefix = dir//"/serial_"//int_str(np)
         command = "OMP_NUM_THREADS="//int_str(cores)//" "//self_path()//" run --solver cg --lower '"//heights// &
            ":/heights' --pixel "//real_str(deck%pixel, 17)//common//" -o '"//prefix//"'"
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
            int_str(nint(json_value(text, '"cg_iterations"')))//" | | "// &
            fixed_str(100*json_value(text, '"area_fraction"'), 2)//" | (reference) |"
         flush(output_unit)
         do r = 1, size(ranks)
            threads = max(1, cores/ranks(r))
            prefix = dir//"/mpi_"//int_str(np)//"_"//int_str(ranks(r))
            command = "OMP_NUM_THREADS="//int_str(threads)//" "//mpirun//" -np "//int_str(ranks(r))//" "//program// &
               generated//common//" -o '"//prefix//"'"
            call timed(command, t_run, ios)
            if (ios /= 0) then
               write(output_unit, '(a)') "| "//int_str(np)//" | femcod-mpi | "//int_str(ranks(r))//" x "// &
                  int_str(threads)//" | | | | | | | | exit code "//int_str(ios)//" |"
               cycle
            end if
            text = read_text_file(prefix//".summary.json")
            t_solve = json_value(text, '"solve_time_s"')
            measured(1, n) = json_value(text, '"cg_iterations"') + json_value(text, '"convolutions"')
            if (ranks(r) == 1) measured([2, 3, 4, 5, 6, 9, 10], n) = [real(threads, dp), &
               json_value(text, '"transform_s"'), json_value(text, '"communication_s"'), t_solve, &
               json_list_max(text, '"peak_memory_MB_per_rank"'), json_value(text, '"read_peak_memory_MB"'), &
               json_value(text, '"read_time_s"')]
            if (ranks(r) > 1 .and. ranks(r) >= measured(8, n)) measured(7:8, n) = &
               [json_value(text, '"communication_s"'), real(ranks(r), dp)]
            approach = json_value(text, '"approach_nm"')
            transform = json_value(text, '"transform_s"')
            communication = json_value(text, '"communication_s"')
            write(output_unit, '(a)') "| "//int_str(np)//" | femcod-mpi | "//int_str(ranks(r))//" x "// &
               int_str(threads)//" | "//fixed_str(t_run, 2)//" | "//fixed_str(t_solve, 2)//" | "// &
               int_str(nint(100*transform/max(t_solve, 1.0e-9_dp)))//" | "// &
               int_str(nint(100*communication/max(t_solve, 1.0e-9_dp)))//" | "// &
               int_str(nint(json_value(text, '"cg_iterations"')))//" (+"// &
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
   end subroutine bench_mpi

   !> `femcod bench mpi --help`.
   subroutine print_mpi_help()
      write(output_unit, '(a)') "usage: femcod bench mpi [--np 1024,2048,4096] [--ranks 1,2] [--contact 1] [--tol 1e-8]", &
         "                        [--dir DIR] [--mpirun CMD] [--femcod-mpi PATH]", &
         "The whole femcod-mpi command (bash setup.sh --mpi) under CMD -np P for each P of --ranks, each", &
         "rank with cores/P OpenMP threads, against the whole serial femcod run --solver cg on all cores:", &
         "the benchmark surface (self-affine, Hurst 0.8, rms 3 nm, 5 um square, rigid flat, seed 1),", &
         "read by femcod run from DIR/surface_NP.h5:/heights (written once per NP) and made by", &
         "femcod-mpi on its ranks (--generate self-affine, the same surface), at the load of about --contact % contact", &
         "(the linear law of femcod bench cg). As root, CMD gets --allow-run-as-root.", &
         "Then the estimate for 16384^2 to 65536^2 on 16 to 1024 ranks (one core each, --cores-per-node", &
         "per node, --network GB/s per node, --latency us per message), from this run's measured costs,", &
         "the input path (the surface made on the ranks) included (the method is printed).", ""
      call print_lines(option_help(bench_mpi_table(), ""))
      write(output_unit, '(a)') "Columns: NP, run, ranks x threads, whole command s, solve s, transforms % and", &
         "communication % of the solve (rank 0: the 1-D FFTs; the transposes, FFTW-MPI's or on one node", &
         "through shared memory, the sums and halos, waiting included), iterations (+ coarse, fresh", &
         "convolutions), peak MB of the largest rank,", &
         "contact %, approach's difference from the serial run's (relative)."
   end subroutine print_mpi_help

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
   !> `latency_us` each. Memory per rank: the 1-rank peak per pixel over P. The input path
   !> (the surface made on the ranks, and the grid's set-up): its 1-rank seconds per
   !> pixel and log2(NP) (an FFT of the surface), divided over the ranks; its peak per
   !> pixel (the spectrum and the surface) over P, before the solve allocates.
   subroutine print_mpi_estimate(sizes, measured, per_node, network, latency_us)
      integer, intent(in) :: sizes(:)
      real(dp), intent(in) :: measured(:, :)
      integer, intent(in) :: per_node
      !> GB/s per node between nodes, and us per message.
      real(dp), intent(in) :: network, latency_us
      integer, parameter :: targets(3) = [16384, 32768, 65536], rank_counts(4) = [16, 64, 256, 1024]
      real(dp) :: beta, sx, sy, sxx, sxy, k, r, bytes_px, read_px, local_rate, np0, conv0, conv, compute, moving, &
         latency, x, y, input_k, input
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
      input_k = measured(10, base)*measured(2, base)/(np0**2*log(np0)/log(2.0_dp))
      local_rate = 0
      if (measured(7, base) > 0) local_rate = 32*np0**2/(measured(7, base)/conv0)
      write(output_unit, '(a)') "", "Estimate (from NP = "//int_str(sizes(base))//" on 1 rank x "// &
         int_str(nint(measured(2, base)))//" threads: "//real_str(k, 3)//" core-s per pixel and log2(2 NP) in the "// &
         "transforms and "//real_str(r, 3)//" core-s per pixel in the rest, per convolution; "// &
         int_str(nint(bytes_px))//" bytes per pixel, "//int_str(nint(read_px))//" while making the input; "// &
         "the input "//real_str(input_k, 3)//" core-s per pixel and log2(NP); "// &
         "convolutions ~ NP^"//fixed_str(beta, 2)//" from "// &
         int_str(count)//" sizes; within a node the transposes move "//real_str(local_rate/1.0e9_dp, 2)// &
         " GB/s on "//int_str(nint(measured(8, base)))//" ranks (measured; P ranks in one node taken to move P/"// &
         int_str(nint(measured(8, base)))//" times as much), between nodes "// &
         fixed_str(network, 1)//" GB/s per node and "//fixed_str(latency_us, 1)//" us per message, "// &
         int_str(per_node)//" ranks per node):"
      ! The model's own check: twice and four times the base NP on this machine's cores (1
      ! rank with the measured threads, and the measured larger rank count sharing them).
      do t = 1, 2
         x = 2**t*np0
         conv = conv0*(2.0_dp**t)**beta
         compute = (k*x**2*log(2*x)/log(2.0_dp) + r*x**2)/measured(2, base)
         input = input_k*x**2*log(x)/log(2.0_dp)/measured(2, base)
         write(output_unit, '(a)') "", "Check on this machine, NP = "//int_str(nint(x))//": "//int_str(nint(conv))// &
            " convolutions, "//int_str(nint(conv*(compute + measured(4, base)/conv0*4)))//" s to solve and "// &
            fixed_str(input, 1)//" s of input on 1 rank x "//int_str(nint(measured(2, base)))//" threads"
         if (local_rate > 0) write(output_unit, '(a)') "  and "//int_str(nint(conv*(compute + 32*x**2/local_rate)))// &
            " s on "//int_str(nint(measured(8, base)))//" ranks sharing the same cores (run --np "//int_str(nint(x))// &
            " to compare)."
      end do
      write(output_unit, '(a)') "", "| NP | ranks | nodes | memory per rank GB (input GB) | convolutions | "// &
         "compute s / convolution | transposes s / convolution | solve estimate s | input s | whole estimate s |"
      write(output_unit, '(a)') "|---|---|---|---|---|---|---|---|---|---|"
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
            input = input_k*x**2*log(x)/log(2.0_dp)/rank_counts(p)
            write(output_unit, '(a)') "| "//int_str(targets(t))//" | "//int_str(rank_counts(p))//" | "// &
               int_str(nodes)//" | "//fixed_str(bytes_px*x**2/rank_counts(p)/1.0e9_dp, 2)//" ("// &
               fixed_str(read_px*x**2/rank_counts(p)/1.0e9_dp, 2)//") | "//int_str(nint(conv))//" | "// &
               fixed_str(compute, 3)//" | "//fixed_str(moving + latency, 3)//" | "// &
               int_str(nint(conv*(compute + moving + latency)))//" | "//fixed_str(input, 1)//" | "// &
               int_str(nint(conv*(compute + moving + latency) + input))//" |"
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
   !> Before any work: the launcher and femcod-mpi exist (exit 2), the directory can be
   !> made, and no height file it is about to write replaces one femcod did not write.
   !> As root, the launcher gains --allow-run-as-root.
   subroutine check_before_work(sizes, dir, mpirun, program, code)
      integer, intent(in) :: sizes(:)
      character(len=:), allocatable, intent(inout) :: mpirun
      character(len=*), intent(in) :: dir, program
      integer, intent(inout) :: code
      type(string_type), allocatable :: surfaces(:)
      integer :: n
      call require_program("--mpirun", mpirun, "mpi", code)
      call require_program("--femcod-mpi", program, "mpi", code)
      call prepare_directory(dir, "mpi", code)
      allocate(surfaces(size(sizes)))
      do n = 1, size(sizes)
         surfaces(n)%s = dir//"/surface_"//int_str(sizes(n))//".h5"
      end do
      call guard_bench_files(surfaces, OUTPUT_RESULT, "mpi", code)
      if (is_root()) mpirun = mpirun//" --allow-run-as-root"
   end subroutine check_before_work

   !> True when this process runs as root (mpirun then needs --allow-run-as-root).
   logical function is_root()
      integer :: stat
      call execute_command_line('test "$(id -u)" -eq 0', exitstat=stat)
      is_root = stat == 0
   end function is_root

end module femcod_bench_mpi
