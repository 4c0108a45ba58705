!> OpenBLAS 0.3.21 (Debian 12) does not recognise recent Xeons (Cooper Lake, Sapphire
!> Rapids): it falls back to its generic "Prescott" kernels, and the BLAS-3 triangular
!> solves of the incremental solver run 3 to 4 times slower (doc/performance.md). And its
!> idle threads wait by calling sched_yield for 2^28 cycles (about 0.1 s) after the
!> library is loaded and after each threaded call before they sleep: on 2 cores the
!> waiting thread took a core from femcod's own threads reading a deck (1024^2: 0.14
!> instead of 0.08 s) and cost 3.5 s of system time in a 5 s incremental run.
!> OpenBLAS reads OPENBLAS_CORETYPE and OPENBLAS_THREAD_TIMEOUT once, when the library is
!> loaded, so femcod sets those that are unset (the core from the CPU's flags, avx512f:
!> SkylakeX, avx2: Haswell; the wait to 2^4 cycles) and starts itself again, once. A
!> user's own values are never touched; with another BLAS the variables are ignored.
module femcod_blas_core
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_ptr, c_null_char, c_null_ptr, c_loc
   implicit none
   private
   public :: select_blas_core

   interface
      function c_setenv(name, value, overwrite) bind(c, name="setenv") result(rc)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: name(*), value(*)
         integer(c_int), value :: overwrite
         integer(c_int) :: rc
      end function c_setenv
      function c_execv(path, argv) bind(c, name="execv") result(rc)
         import :: c_char, c_int, c_ptr
         character(kind=c_char), intent(in) :: path(*)
         type(c_ptr), intent(in) :: argv(*)
         integer(c_int) :: rc
      end function c_execv
   end interface

   !> One argument as a C string, kept alive for execv.
   type :: c_string
      character(kind=c_char, len=:), allocatable :: s
   end type c_string

contains

   subroutine select_blas_core()
      character(len=:), allocatable :: core
      type(c_string), allocatable, target :: args(:)
      type(c_ptr), allocatable :: argv(:)
      integer :: status, n, k, length
      logical :: changed
      changed = .false.
      call get_environment_variable("OPENBLAS_CORETYPE", status=status)
      if (status == 1) then
         core = core_from_cpu_flags()
         if (core /= "") changed = c_setenv("OPENBLAS_CORETYPE"//c_null_char, core//c_null_char, 1_c_int) == 0
      end if
      call get_environment_variable("OPENBLAS_THREAD_TIMEOUT", status=status)
      if (status == 1) then
         if (c_setenv("OPENBLAS_THREAD_TIMEOUT"//c_null_char, "4"//c_null_char, 1_c_int) == 0) changed = .true.
      end if
      if (.not. changed) return
      n = command_argument_count()
      allocate(args(0:n), argv(0:n + 1))
      do k = 0, n
         call get_command_argument(k, length=length)
         allocate(character(kind=c_char, len=length + 1) :: args(k)%s)
         call get_command_argument(k, args(k)%s(1:length))
         args(k)%s(length + 1:length + 1) = c_null_char
         argv(k) = c_loc(args(k)%s)
      end do
      argv(n + 1) = c_null_ptr
      ! Only returns if the exec failed; then femcod simply goes on as it is.
      status = c_execv("/proc/self/exe"//c_null_char, argv)
   end subroutine select_blas_core

   !> SkylakeX, Haswell or "" from the first flags line of /proc/cpuinfo.
   function core_from_cpu_flags() result(core)
      character(len=:), allocatable :: core
      character(len=8192) :: line
      integer :: unit, ios
      core = ""
      open(newunit=unit, file="/proc/cpuinfo", action="read", status="old", iostat=ios)
      if (ios /= 0) return
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:5) /= "flags") cycle
         if (index(line//" ", " avx512f ") > 0) then
            core = "SkylakeX"
         else if (index(line//" ", " avx2 ") > 0) then
            core = "Haswell"
         end if
         exit
      end do
      close(unit)
   end function core_from_cpu_flags
end module femcod_blas_core
