!> A project-local implementation of the public API of fortran-lang/test-drive
!> (v0.6 names: error_type, unittest_type, testsuite_type, new_unittest,
!> new_testsuite, run_testsuite, run_selected, select_suite, select_test, check,
!> test_failed, skip_test, to_string), written from scratch because git hosts are out
!> of reach here. To use the upstream package instead, delete this file and add to
!> fpm.toml:  [dev-dependencies] test-drive.git = "https://github.com/fortran-lang/test-drive"
!> (tag = "v0.6.1"). Suites run serially (serial HDF5 and the FFTW planner are not
!> thread-safe).
module testdrive
   use, intrinsic :: iso_fortran_env, only: dp => real64, output_unit
   implicit none
   private
   public :: error_type, unittest_type, testsuite_type, new_unittest, new_testsuite
   public :: run_testsuite, run_selected, select_suite, select_test
   public :: check, test_failed, skip_test, to_string, test_interface, collect_interface
   public :: count_tests, tests_skipped

   !> Outcome of a failed or skipped test: stat 1 failed, 77 skipped.
   type :: error_type
      integer :: stat = 0
      character(len=:), allocatable :: message
   end type error_type

   integer, parameter :: success = 0, fatal = 1, skipped = 77

   abstract interface
      subroutine test_interface(error)
         import :: error_type
         type(error_type), allocatable, intent(out) :: error
      end subroutine test_interface
   end interface

   !> One test.
   type :: unittest_type
      character(len=:), allocatable :: name
      procedure(test_interface), pointer, nopass :: test => null()
      logical :: should_fail = .false.
   end type unittest_type

   abstract interface
      subroutine collect_interface(testsuite)
         import :: unittest_type
         type(unittest_type), allocatable, intent(out) :: testsuite(:)
      end subroutine collect_interface
   end interface

   !> A named collection of tests.
   type :: testsuite_type
      character(len=:), allocatable :: name
      procedure(collect_interface), pointer, nopass :: collect => null()
   end type testsuite_type

   interface check
      module procedure :: check_stat, check_logical, check_bool, check_int, check_string, check_float_dp
   end interface check

   interface to_string
      module procedure :: int_to_string, real_to_string
   end interface to_string

   !> Number of tests skipped so far (for the closing line).
   integer, save :: tests_skipped = 0

contains

   function new_unittest(name, test, should_fail) result(self)
      character(len=*), intent(in) :: name
      procedure(test_interface) :: test
      logical, intent(in), optional :: should_fail
      type(unittest_type) :: self
      self%name = name
      self%test => test
      if (present(should_fail)) self%should_fail = should_fail
   end function new_unittest

   function new_testsuite(name, collect) result(self)
      character(len=*), intent(in) :: name
      procedure(collect_interface) :: collect
      type(testsuite_type) :: self
      self%name = name
      self%collect => collect
   end function new_testsuite

   !> Number of tests a suite holds.
   integer function count_tests(collect)
      procedure(collect_interface) :: collect
      type(unittest_type), allocatable :: tests(:)
      call collect(tests)
      count_tests = size(tests)
   end function count_tests

   !> Run every test of a suite; `stat` is increased by the number of failures.
   subroutine run_testsuite(collect, unit, stat, parallel)
      procedure(collect_interface) :: collect
      integer, intent(in) :: unit
      integer, intent(inout) :: stat
      logical, intent(in), optional :: parallel
      type(unittest_type), allocatable :: tests(:)
      integer :: i
      call collect(tests)
      do i = 1, size(tests)
         call run_unittest(tests(i), unit, stat)
      end do
      if (present(parallel)) continue
   end subroutine run_testsuite

   !> Run the test of that name; unknown names count as a failure.
   subroutine run_selected(collect, name, unit, stat)
      procedure(collect_interface) :: collect
      character(len=*), intent(in) :: name
      integer, intent(in) :: unit
      integer, intent(inout) :: stat
      type(unittest_type), allocatable :: tests(:)
      integer :: i
      call collect(tests)
      i = select_test(tests, name)
      if (i > 0 .and. i <= size(tests)) then
         call run_unittest(tests(i), unit, stat)
      else
         write(unit, '(a)') "  no test named '"//name//"'"
         stat = stat + 1
      end if
   end subroutine run_selected

   subroutine run_unittest(test, unit, stat)
      type(unittest_type), intent(in) :: test
      integer, intent(in) :: unit
      integer, intent(inout) :: stat
      type(error_type), allocatable :: error
      character(len=:), allocatable :: message
      call test%test(error)
      if (allocated(error)) then
         if (error%stat == skipped) then
            tests_skipped = tests_skipped + 1
            message = "  SKIPPED  "//test%name
            if (allocated(error%message)) message = message//": "//error%message
            write(unit, '(a)') message
            return
         end if
      end if
      if (allocated(error) .neqv. test%should_fail) then
         stat = stat + 1
         message = "  FAILED   "//test%name
         if (allocated(error)) then
            if (allocated(error%message)) message = message//new_line("a")//"           "//error%message
         else
            message = message//" (expected to fail)"
         end if
         write(unit, '(a)') message
      else
         write(unit, '(a)') "  passed   "//test%name
      end if
   end subroutine run_unittest

   integer function select_suite(suites, name) result(pos)
      type(testsuite_type), intent(in) :: suites(:)
      character(len=*), intent(in) :: name
      integer :: i
      pos = 0
      do i = 1, size(suites)
         if (suites(i)%name == name) then
            pos = i
            return
         end if
      end do
   end function select_suite

   integer function select_test(tests, name) result(pos)
      type(unittest_type), intent(in) :: tests(:)
      character(len=*), intent(in) :: name
      integer :: i
      pos = 0
      do i = 1, size(tests)
         if (tests(i)%name == name) then
            pos = i
            return
         end if
      end do
   end function select_test

   subroutine test_failed(error, message, more)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      character(len=*), intent(in), optional :: more
      allocate(error)
      error%stat = fatal
      error%message = message
      if (present(more)) error%message = message//new_line("a")//"           "//more
   end subroutine test_failed

   subroutine skip_test(error, message, more)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: message, more
      allocate(error)
      error%stat = skipped
      error%message = "skipped"
      if (present(message)) error%message = message
      if (present(more)) error%message = error%message//" "//more
   end subroutine skip_test

   subroutine fail(error, default, message, more)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: default
      character(len=*), intent(in), optional :: message, more
      if (present(message)) then
         call test_failed(error, message, more)
      else
         call test_failed(error, default, more)
      end if
   end subroutine fail

   subroutine check_stat(error, stat, message, more)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: stat
      character(len=*), intent(in), optional :: message, more
      if (stat /= success) call fail(error, "non-zero exit code "//to_string(stat), message, more)
   end subroutine check_stat

   subroutine check_logical(error, expression, message, more)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: expression
      character(len=*), intent(in), optional :: message, more
      if (.not. expression) call fail(error, "condition not fulfilled", message, more)
   end subroutine check_logical

   subroutine check_bool(error, actual, expected, message, more)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: actual, expected
      character(len=*), intent(in), optional :: message, more
      if (actual .neqv. expected) call fail(error, "logical value mismatch", message, more)
   end subroutine check_bool

   subroutine check_int(error, actual, expected, message, more)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: actual, expected
      character(len=*), intent(in), optional :: message, more
      if (actual /= expected) call fail(error, "integer mismatch: expected "//to_string(expected)// &
         ", got "//to_string(actual), message, more)
   end subroutine check_int

   subroutine check_string(error, actual, expected, message, more)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: actual, expected
      character(len=*), intent(in), optional :: message, more
      if (actual /= expected) call fail(error, "string mismatch: expected '"//expected//"', got '"// &
         actual//"'", message, more)
   end subroutine check_string

   !> Real comparison: relative (`rel=.true.`) or absolute, within `thr`
   !> (default: exact to a few ulps, as upstream: epsilon(expected)).
   subroutine check_float_dp(error, actual, expected, message, more, thr, rel)
      type(error_type), allocatable, intent(out) :: error
      real(dp), intent(in) :: actual, expected
      character(len=*), intent(in), optional :: message, more
      real(dp), intent(in), optional :: thr
      logical, intent(in), optional :: rel
      real(dp) :: diff, threshold
      logical :: relative
      threshold = epsilon(expected)
      if (present(thr)) threshold = thr
      relative = .false.
      if (present(rel)) relative = rel
      diff = abs(actual - expected)
      if (relative .and. expected /= 0) diff = diff/abs(expected)
      if (.not. diff <= threshold) then
         call fail(error, "real mismatch: expected "//to_string(expected)//", got "//to_string(actual)// &
            merge(" (relative difference ", " (difference          ", relative)//to_string(diff)//")", &
            message, more)
      end if
   end subroutine check_float_dp

   pure function int_to_string(i) result(s)
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      character(len=16) :: buf
      write(buf, '(i0)') i
      s = trim(buf)
   end function int_to_string

   function real_to_string(x) result(s)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=32) :: buf
      write(buf, '(es24.16e3)') x
      s = trim(adjustl(buf))
   end function real_to_string
end module testdrive
