!> femcod test driver: runs every suite serially and closes with "N passed, N failed".
!> `fpm test -- SUITE [TEST]` runs one suite or one test.
!> `fpm test --profile release -- --stability-report FILE [--events N]` runs the hard cases
!> of the stability suite with their references and writes doc/stability.md (FILE).
program tester
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use testdrive, only: run_testsuite, run_selected, new_testsuite, testsuite_type, select_suite, count_tests, &
      tests_skipped
   use test_deck, only: collect_deck
   use test_deck_h5, only: collect_deck_h5
   use test_workspace, only: collect_workspace
   use test_sort, only: collect_sort
   use test_surfaces, only: collect_surfaces
   use test_boussinesq, only: collect_boussinesq
   use test_legacy, only: collect_legacy
   use test_incremental, only: collect_incremental
   use test_results, only: collect_results
   use test_hostile, only: collect_hostile
   use test_stability, only: collect_stability
   use test_cg, only: collect_cg
   use test_periodic, only: collect_periodic
   use test_adhesion, only: collect_adhesion
   use test_studies, only: collect_studies
   use test_options, only: collect_options
   use test_heights, only: collect_heights
   use test_safety, only: collect_safety
   use test_architecture, only: collect_architecture
   use test_matrix, only: collect_matrix
   use test_friction, only: collect_friction
   use test_tangential, only: collect_tangential
   use test_patches, only: collect_patches
   use test_refine, only: collect_refine
   use test_silent, only: collect_silent
   use test_report, only: collect_report
   use femcod_exit, only: exit_program
   use femcod_cli, only: run_femcod, command_arguments
   use femcod_strings, only: string_type, parse_integer
   use femcod_status, only: status_type
   use stability_report, only: write_stability_report
   implicit none
   type(testsuite_type), allocatable :: suites(:)
   integer :: stat, is, total, nargs
   character(len=128) :: suite_name, test_name

   suites = [ &
      new_testsuite("deck", collect_deck), &
      new_testsuite("deck_h5", collect_deck_h5), &
      new_testsuite("workspace", collect_workspace), &
      new_testsuite("sort", collect_sort), &
      new_testsuite("surfaces", collect_surfaces), &
      new_testsuite("boussinesq", collect_boussinesq), &
      new_testsuite("legacy", collect_legacy), &
      new_testsuite("silent", collect_silent), &
      new_testsuite("incremental", collect_incremental), &
      new_testsuite("results", collect_results), &
      new_testsuite("report", collect_report), &
      new_testsuite("hostile", collect_hostile), &
      new_testsuite("stability", collect_stability), &
      new_testsuite("cg", collect_cg), &
      new_testsuite("periodic", collect_periodic), &
      new_testsuite("adhesion", collect_adhesion), &
      new_testsuite("friction", collect_friction), &
      new_testsuite("tangential", collect_tangential), &
      new_testsuite("patches", collect_patches), &
      new_testsuite("refine", collect_refine), &
      new_testsuite("studies", collect_studies), &
      new_testsuite("options", collect_options), &
      new_testsuite("heights", collect_heights), &
      new_testsuite("safety", collect_safety), &
      new_testsuite("architecture", collect_architecture), &
      new_testsuite("matrix", collect_matrix) &
      ]
   stat = 0
   total = 0
   nargs = command_argument_count()
   if (nargs >= 1) then
      call get_command_argument(1, suite_name)
      if (suite_name == "--femcod") then
         ! The tests that need a separate process (killed runs, captured messages) run
         ! this executable as femcod: `tester --femcod ARGS` is `femcod ARGS`.
         block
            type(string_type), allocatable :: args(:)
            integer :: code
            args = command_arguments()
            call run_femcod(args(2:), code)
            call exit_program(code)
         end block
      end if
      if (suite_name == "--stability-report") then
         block
            type(string_type), allocatable :: args(:)
            type(status_type) :: status
            integer :: events
            logical :: ok
            args = command_arguments()
            events = 5000
            ok = size(args) == 2
            if (size(args) == 4) then
               ok = args(3)%s == "--events"
               if (ok) call parse_integer(args(4)%s, events, ok)
               ok = ok .and. events >= 2
            end if
            if (.not. ok) then
               write(error_unit, '(a)') "usage: --stability-report FILE [--events N (>= 2)]"
               call exit_program(2)
            end if
            call write_stability_report(args(2)%s, events, status, .true.)
            if (status%code /= 0) write(error_unit, '(a)') status%message
            if (status%code == 0) write(output_unit, '(a)') "wrote "//args(2)%s
            call exit_program(status%code)
         end block
      end if
      is = select_suite(suites, trim(suite_name))
      if (is == 0) then
         write(error_unit, '(a)') "no suite named "//trim(suite_name)
         call exit_program(1)
      end if
      write(output_unit, '(a)') "# suite "//suites(is)%name
      if (nargs >= 2) then
         call get_command_argument(2, test_name)
         call run_selected(suites(is)%collect, trim(test_name), output_unit, stat)
         total = 1
      else
         call run_testsuite(suites(is)%collect, output_unit, stat)
         total = count_tests(suites(is)%collect)
      end if
   else
      do is = 1, size(suites)
         write(output_unit, '(a)') "# suite "//suites(is)%name
         call run_testsuite(suites(is)%collect, output_unit, stat, parallel=.false.)
         total = total + count_tests(suites(is)%collect)
      end do
   end if
   write(output_unit, '(i0,a,i0,a,i0,a)') total - stat - tests_skipped, " passed, ", stat, " failed, ", &
      tests_skipped, " skipped"
   if (stat > 0) call exit_program(1)
end program tester
