!> `femcod report PREFIX|DIR [-o FILE] [--force] [-q]`: one self-contained HTML page of
!> a run's or a study's results, or of a directory of results (io/femcod_report).
module femcod_report_command
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_clock, only: wall_clock
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_IO
   use femcod_strings, only: string_type, int_str, sig_str
   use femcod_files, only: path_exists, path_is_directory, write_file
   use femcod_report, only: report_page, batch_page
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, flag_option, text_option, &
      get_option, option_given
   implicit none
   private
   public :: report_command, report_table, make_report

contains

   function report_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [text_option("--output", "FILE", "the page (default PREFIX.report.html; for a directory DIR/"// &
         "report.html, with each run's PREFIX.report.html beside it)", alias="-o"), &
         flag_option("--force", "replace an existing FILE given by -o (the default names are femcod's own and "// &
         "are replaced)"), &
         flag_option("--quiet", "print nothing on standard output", alias="-q")]
   end function report_table

   subroutine report_help()
      write(output_unit, '(a)') &
         "usage: femcod report PREFIX [-o FILE] [--force] [-q]", &
         "       femcod report DIR [-o FILE] [--force] [-q]", &
         "", &
         "One self-contained HTML page of results (no network, no external file: it opens from a laptop's", &
         "disk as from a cluster's file system), made from the files femcod wrote, so it can be made again", &
         "wherever they are copied:", &
         "  PREFIX of `femcod run -o PREFIX`: the run (deck, options, version, machine, times, memory, how", &
         "    it ended), the load-approach curve (with Hertz' or the flat punch's closed form for a mkdeck", &
         "    sphere or circular punch), the area-load curve and its power law, the states' table and the", &
         "    pressure, gap, plastic and stick/slip maps of up to 10 states, the contact patches (count", &
         "    against load, sizes, perimeter against area), the solver's checks and every summary value;", &
         "  PREFIX of a study (resolution, summits, multiscale, refine): its tables and figures;", &
         "  DIR, a directory of results (femcod run --outdir DIR): one sortable table of every run, all", &
         "    area-load curves in one figure, the failed decks of a batch with their messages", &
         "    (PREFIX.failed.json), and each run's own page beside it.", &
         "Maps above 1024 x 1024 pixels are drawn by blocks (each block's largest pressure, smallest gap).", &
         ""
      call print_lines(option_help(report_table(), ""))
      write(output_unit, '(a)') "", "exit codes: 0 ok, 2 usage, 3 bad input (missing or unreadable results), 5 I/O"
   end subroutine report_help

   !> `femcod report ARGS`.
   subroutine report_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(parsed_options) :: parsed
      type(status_type) :: status
      character(len=:), allocatable :: output
      type(string_type), allocatable :: written(:)
      real(dp) :: t0, t1
      integer :: k, bytes
      code = 0
      if (help_requested(args)) then
         call report_help()
         return
      end if
      call parse_options(report_table(), args, parsed, status)
      if (status%code == 0 .and. size(parsed%positional) /= 1) call set_error(status, STATUS_USAGE, &
         "expected one PREFIX or DIR, found "//int_str(size(parsed%positional)))
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod report: "//status%message//" (femcod report --help)"
         code = status%code
         return
      end if
      call wall_clock(t0)
      output = ""
      call get_option(parsed, "--output", output)
      call make_report(parsed%positional(1)%s, output, option_given(parsed, "--force"), written, bytes, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod report: "//status%message
         code = status%code
         return
      end if
      call wall_clock(t1)
      if (.not. option_given(parsed, "--quiet")) then
         do k = 1, size(written)
            write(output_unit, '(a)') "  wrote "//written(k)%s
         end do
         write(output_unit, '(a)') "femcod report: wrote "//output//" ("//int_str(bytes)//" bytes, "// &
            sig_str(t1 - t0, 3)//" s)"
      end if
   end subroutine report_command

   !> The page of `target` (a results prefix or a directory) in `output` ("": the default
   !> name, set here). An existing `output` given by the caller is replaced only with
   !> `force`. `written` lists each run's page of a directory; `bytes` the page's size.
   !> No printing: `femcod report` and libfemcod's femcod_report share it.
   subroutine make_report(target_given, output, force, written, bytes, status)
      character(len=*), intent(in) :: target_given
      character(len=:), allocatable, intent(inout) :: output
      logical, intent(in) :: force
      type(string_type), allocatable, intent(out) :: written(:)
      integer, intent(out) :: bytes
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: target, html
      allocate(written(0))
      bytes = 0
      target = target_given
      do while (len(target) > 1 .and. target(len(target):) == "/")
         target = target(1:len(target) - 1)
      end do
      if (output /= "" .and. path_exists(output) .and. .not. force) call set_error(status, STATUS_IO, &
         output//": exists; femcod report replaces a FILE given by -o only with --force")
      if (status%code /= 0) return
      if (path_is_directory(target)) then
         if (output == "") output = target//"/report.html"
         call batch_page(target, written, html, status)
      else
         if (output == "") output = target//".report.html"
         call report_page(target, html, status)
      end if
      if (status%code == 0) call write_file(output, html, status)
      if (status%code == 0) bytes = len(html)
   end subroutine make_report
end module femcod_report_command
