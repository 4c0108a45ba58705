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
!>
!> libgomp's threads spin at each barrier before they sleep (OMP_WAIT_POLICY unset): when
!> another process is busy on the cores, a spinning thread takes the core the thread it
!> waits for needs, and two threads ran slower than one (doc/performance.md, threads on a
!> busy machine). libgomp reads its wait policy once, when it is loaded. So when neither
!> OMP_WAIT_POLICY nor GOMP_SPINCOUNT is set, more than one thread would run, the process
!> is not bound to some of the cpus (as a batch system binds a job to its own), and the
!> tasks already running elsewhere leave fewer cpus than threads, femcod sets
!> OMP_WAIT_POLICY=passive (threads sleep at once) and FEMCOD_BUSY_AT_START (what it saw,
!> for the run's summary) before the same restart. A quiet machine keeps the default; a
!> load that comes later is not followed.
module femcod_start_environment
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_ptr, c_null_char, c_null_ptr, c_loc
   !$ use omp_lib, only: omp_get_max_threads, omp_get_num_procs
   use femcod_files, only: directory_names
   use femcod_status, only: status_type
   use femcod_strings, only: string_type
   implicit none
   private
   public :: prepare_environment

   interface
      function c_setenv(name, value, overwrite) bind(c, name="setenv") result(rc)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: name(*), value(*)
         integer(c_int), value :: overwrite
         integer(c_int) :: rc
      end function c_setenv
      function c_usleep(microseconds) bind(c, name="usleep") result(rc)
         import :: c_int
         integer(c_int), value :: microseconds
         integer(c_int) :: rc
      end function c_usleep
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

   !> Set the unset OpenBLAS variables and, on a busy machine, the wait policy; start the
   !> program again when anything was set (the loaded libraries read them only then).
   subroutine prepare_environment()
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
      if (choose_passive_wait()) changed = .true.
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
   end subroutine prepare_environment

   !> OMP_WAIT_POLICY=passive when neither it nor GOMP_SPINCOUNT is set, more than one
   !> OpenMP thread would run, the process may run on every cpu of the machine, and the
   !> tasks running besides it (processes_running) plus the threads exceed the machine's
   !> cpus. True when the variables were set.
   logical function choose_passive_wait() result(chosen)
      integer :: status, others, cpus, threads
      character(len=80) :: seen
      chosen = .false.
      call get_environment_variable("OMP_WAIT_POLICY", status=status)
      if (status /= 1) return
      call get_environment_variable("GOMP_SPINCOUNT", status=status)
      if (status /= 1) return
      threads = 1
      !$ threads = omp_get_max_threads()
      if (threads < 2) return
      call processes_running(others, cpus)
      if (others < 1 .or. cpus < 1 .or. others + threads <= cpus) return
      ! Confined to some of the cpus (a batch system's binding): the other tasks counted
      ! are likely on the cpus it is not given, which /proc/stat does not tell apart.
      !$ if (omp_get_num_procs() < cpus) return
      if (c_setenv("OMP_WAIT_POLICY"//c_null_char, "passive"//c_null_char, 1_c_int) /= 0) return
      if (others == 1) then
         write(seen, '(a,i0,a)') "1 other task running at start, ", cpus, " cpus"
      else
         write(seen, '(i0,a,i0,a)') others, " other tasks running at start, ", cpus, " cpus"
      end if
      chosen = c_setenv("FEMCOD_BUSY_AT_START"//c_null_char, trim(seen)//c_null_char, 1_c_int) == 0
   end function choose_passive_wait

   !> The tasks running besides this process's own (procs_running in /proc/stat less this
   !> process's threads in state R, the fewest of 10 looks 1 ms apart: OpenBLAS's threads
   !> may be spinning just after it was loaded) and the machine's cpus (the cpuN lines of
   !> /proc/stat); -1 each when /proc cannot be read.
   subroutine processes_running(others, cpus)
      integer, intent(out) :: others, cpus
      integer :: look, running, own
      others = -1
      do look = 1, 10
         call read_proc_stat(running, cpus)
         own = own_running_threads()
         if (running < 0 .or. own < 0) return
         if (others < 0 .or. running - own < others) others = max(0, running - own)
         if (others == 0) return
         if (c_usleep(1000_c_int) /= 0) return
      end do
   end subroutine processes_running

   !> procs_running and the count of cpuN lines of /proc/stat (-1 each if unreadable).
   subroutine read_proc_stat(running, cpus)
      integer, intent(out) :: running, cpus
      character(len=256) :: line
      integer :: unit, ios
      running = -1
      cpus = -1
      open(newunit=unit, file="/proc/stat", action="read", status="old", iostat=ios)
      if (ios /= 0) return
      cpus = 0
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:3) == "cpu" .and. verify(line(4:4), "0123456789") == 0) cpus = cpus + 1
         if (line(1:14) == "procs_running ") then
            read(line(15:), *, iostat=ios) running
            if (ios /= 0) running = -1
            exit
         end if
      end do
      close(unit)
   end subroutine read_proc_stat

   !> This process's threads in state R (/proc/self/task/TID/stat: the letter after the
   !> command's closing parenthesis); -1 if they cannot be read.
   integer function own_running_threads() result(own)
      type(string_type), allocatable :: tasks(:)
      type(status_type) :: status
      character(len=512) :: line
      integer :: k, unit, ios, close_paren
      own = -1
      call directory_names("/proc/self/task", tasks, status)
      if (status%code /= 0 .or. size(tasks) == 0) return
      own = 0
      do k = 1, size(tasks)
         open(newunit=unit, file="/proc/self/task/"//tasks(k)%s//"/stat", action="read", status="old", iostat=ios)
         if (ios /= 0) cycle
         read(unit, '(a)', iostat=ios) line
         close(unit)
         if (ios /= 0) cycle
         close_paren = index(line, ")", back=.true.)
         if (close_paren > 0 .and. close_paren + 2 <= len(line)) then
            if (line(close_paren + 2:close_paren + 2) == "R") own = own + 1
         end if
      end do
   end function own_running_threads

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
end module femcod_start_environment
