!> `femcod bench io`: the whole `femcod run` command, reading and writing included.
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_io
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, option_help, text_option, integer_list_option, get_option
   use femcod_clock, only: wall_clock
   use femcod_deck, only: write_deck
   use femcod_files, only: write_file
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_read
   use femcod_svg, only: svg_pressure_map
   use femcod_output_guard, only: OUTPUT_DECK, OUTPUT_RESULT
   use femcod_bench_common, only: prepare_directory, guard_bench_files, &
      bench_arguments, benchmark_surface, linear_law, self_path, json_value, &
      read_text_file, BENCH_LENGTH
   implicit none
   private
   public :: bench_io

contains

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
      type(string_type), allocatable :: decks(:)
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
      call prepare_directory(dir, "io", code)
      allocate(decks(size(sizes)))
      do n = 1, size(sizes)
         decks(n)%s = dir//"/io_"//int_str(sizes(n))//".deck"
      end do
      call guard_bench_files(decks, OUTPUT_DECK, "io", code)
      ! The figure written again here, and each run's outputs, are replaced only where femcod
      ! wrote them (the runs' own guard, with --force, checks theirs).
      call guard_bench_files([string_type(dir//"/figure.svg")], OUTPUT_RESULT, "io", code)
      if (code /= 0) return
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
            ! The run's own cause (2 usage, 3 input, 4 numerical, 5 I/O, 6 stopped) is this
            ! command's; anything else (a signal, a shell's 127) counts as a failure, 4.
            code = 4
            if (ios >= 2 .and. ios <= 6) code = ios
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

   !> The options of `femcod bench io`.
   function bench_io_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [integer_list_option("--np", "N1,...", "grid sizes (default 512,1024,2048)", lower=2), &
         text_option("--dir", "DIR", "where the decks and results go (default femcod-bench-io)")]
   end function bench_io_table
end module femcod_bench_io
