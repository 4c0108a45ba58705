!> The process femcod runs in: its id and host (for locks and the run record), whether
!> another process is alive, and the signals a batch system sends (SIGTERM at a time
!> limit, SIGINT for Ctrl-C, SIGUSR1 as a warning before the limit). A signal only sets
!> a flag here; the solvers look at it between steps (through their observer) and end
!> cleanly. The flag is the one piece of process-wide state in src/: a signal handler
!> has no other way to speak.
module femcod_process
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_size_t, c_null_char, c_funptr, c_funloc
   use, intrinsic :: iso_fortran_env, only: int64
   !$ use omp_lib, only: omp_get_max_threads
   implicit none
   private
   public :: process_id, host_name, openmp_threads, wait_policy_text, process_alive, catch_stop_signals, &
      stop_signal, signal_name, local_time_iso
   public :: SIGINT, SIGTERM, SIGUSR1

   !> Linux signal numbers.
   integer, parameter :: SIGINT = 2, SIGUSR1 = 10, SIGTERM = 15, SIGXFSZ = 25

   !> The last stop signal caught (0: none).
   integer(c_int), volatile :: caught = 0

   interface
      function c_getpid() bind(c, name="getpid") result(pid)
         import :: c_int
         integer(c_int) :: pid
      end function c_getpid
      function c_gethostname(name, length) bind(c, name="gethostname") result(rc)
         import :: c_char, c_size_t, c_int
         character(kind=c_char), intent(out) :: name(*)
         integer(c_size_t), value :: length
         integer(c_int) :: rc
      end function c_gethostname
      function c_signal(sig, handler) bind(c, name="signal") result(old)
         import :: c_int, c_funptr
         integer(c_int), value :: sig
         type(c_funptr), value :: handler
         type(c_funptr) :: old
      end function c_signal
   end interface

contains

   !> This process's id.
   integer function process_id()
      process_id = int(c_getpid())
   end function process_id

   !> This machine's host name ("" if unknown).
   function host_name() result(name)
      character(len=:), allocatable :: name
      character(kind=c_char, len=256) :: buf
      integer :: k
      name = ""
      buf = repeat(c_null_char, len(buf))
      if (c_gethostname(buf, int(len(buf), c_size_t)) /= 0) return
      k = index(buf, c_null_char)
      if (k == 0) k = len(buf) + 1
      name = buf(1:k - 1)
   end function host_name

   !> The OpenMP threads a parallel region runs on (1 without OpenMP).
   integer function openmp_threads()
      openmp_threads = 1
      !$ openmp_threads = omp_get_max_threads()
   end function openmp_threads

   !> How idle OpenMP threads wait: OMP_WAIT_POLICY's value ("default" when unset: libgomp
   !> spins, then sleeps), and why when the femcod program chose it at start
   !> (FEMCOD_BUSY_AT_START, app/femcod_start_environment.f90).
   function wait_policy_text() result(text)
      character(len=:), allocatable :: text, seen
      text = environment_value("OMP_WAIT_POLICY")
      if (text == "") text = "default"
      seen = environment_value("FEMCOD_BUSY_AT_START")
      if (seen /= "") text = text//" (chosen by femcod: "//seen//")"
   end function wait_policy_text

   !> An environment variable's value ("" when unset).
   function environment_value(name) result(value)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: value
      integer :: length, status
      call get_environment_variable(name, length=length, status=status)
      if (status /= 0 .or. length == 0) then
         value = ""
         return
      end if
      allocate(character(len=length) :: value)
      call get_environment_variable(name, value)
   end function environment_value

   !> Whether process `pid` runs on this machine (Linux: /proc/PID/stat exists and its
   !> state is not Z, a zombie, or X, dead: a killed process whose parent is gone stays a
   !> zombie where no init reaps it, as in some containers). A process that is dying is
   !> not running either: one with SIGKILL pending (SigPnd or ShdPnd of /proc/PID/status)
   !> or already exiting (PF_EXITING, 0x4, in the flags of /proc/PID/stat). Without this,
   !> a run started at once after `timeout -s KILL` ended another (timeout kills its whole
   !> group, itself too, and returns before the child has died) found the child still in
   !> its exit and refused the lock it left (the SIGKILL test, once, in a fresh chroot).
   logical function process_alive(pid)
      integer, intent(in) :: pid
      integer(int64), parameter :: PF_EXITING = 4, SIGKILL_BIT = 256
      character(len=32) :: path
      character(len=512) :: line
      integer(int64) :: flags, mask
      integer :: unit, ios, paren, k, field
      process_alive = .false.
      if (pid <= 0) return
      write(path, '("/proc/",i0,"/stat")') pid
      open(newunit=unit, file=trim(path), action="read", status="old", iostat=ios)
      if (ios /= 0) return
      read(unit, '(a)', iostat=ios) line
      close(unit)
      if (ios /= 0) return
      ! "PID (name) S PPID PGRP SESSION TTY TPGID FLAGS ...": the state follows the last
      ! parenthesis, the flags are the seventh field after it.
      paren = index(line, ")", back=.true.)
      if (paren == 0) return
      if (index("ZX", line(paren + 2:paren + 2)) /= 0) return
      k = paren + 1
      do field = 1, 6
         k = k + index(line(k + 1:), " ")
      end do
      read(line(k + 1:), *, iostat=ios) flags
      if (ios == 0) then
         if (iand(flags, PF_EXITING) /= 0) return
      end if
      write(path, '("/proc/",i0,"/status")') pid
      open(newunit=unit, file=trim(path), action="read", status="old", iostat=ios)
      if (ios /= 0) return
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (index(line, "SigPnd:") == 1 .or. index(line, "ShdPnd:") == 1) then
            line = adjustl(line(8:))
            if (line(1:1) == achar(9)) line = adjustl(line(2:))
            read(line, '(z16)', iostat=ios) mask
            if (ios == 0) then
               if (iand(mask, SIGKILL_BIT) /= 0) then
                  close(unit)
                  return
               end if
            end if
         end if
      end do
      close(unit)
      process_alive = .true.
   end function process_alive

   !> From now on SIGTERM, SIGINT and SIGUSR1 set the flag stop_signal() reads instead
   !> of ending the process. SIGXFSZ (a file grew past the job's file-size limit,
   !> `ulimit -f`) no longer kills the process: the write fails with EFBIG instead and is
   !> reported as the I/O error it is, like a full disk.
   subroutine catch_stop_signals()
      type(c_funptr) :: old
      old = c_signal(int(SIGTERM, c_int), c_funloc(on_signal))
      old = c_signal(int(SIGINT, c_int), c_funloc(on_signal))
      old = c_signal(int(SIGUSR1, c_int), c_funloc(on_signal))
      old = c_signal(int(SIGXFSZ, c_int), c_funloc(on_file_size_limit))
   end subroutine catch_stop_signals

   !> SIGXFSZ: nothing to do; the failed write reports it.
   subroutine on_file_size_limit(sig) bind(c)
      integer(c_int), value :: sig
   end subroutine on_file_size_limit

   !> The handler: remember the signal, nothing else (async-signal-safe).
   subroutine on_signal(sig) bind(c)
      integer(c_int), value :: sig
      caught = sig
   end subroutine on_signal

   !> The stop signal caught so far, 0 if none.
   integer function stop_signal()
      stop_signal = int(caught)
   end function stop_signal

   !> "SIGTERM", "SIGINT", "SIGUSR1".
   function signal_name(sig) result(name)
      integer, intent(in) :: sig
      character(len=:), allocatable :: name
      select case (sig)
      case (SIGTERM)
         name = "SIGTERM"
      case (SIGINT)
         name = "SIGINT"
      case (SIGUSR1)
         name = "SIGUSR1"
      case default
         name = "signal"
      end select
   end function signal_name
   !> Now, as ISO 8601 local time with its offset from UTC: 2026-11-23T21:45:07+01:00.
   function local_time_iso() result(stamp)
      character(len=:), allocatable :: stamp
      integer :: v(8), offset
      character(len=32) :: buf
      call date_and_time(values=v)
      offset = abs(v(4))
      write(buf, '(i4.4,"-",i2.2,"-",i2.2,"T",i2.2,":",i2.2,":",i2.2,a1,i2.2,":",i2.2)') v(1), v(2), v(3), &
         v(5), v(6), v(7), merge("+", "-", v(4) >= 0), offset/60, mod(offset, 60)
      stamp = trim(buf)
   end function local_time_iso
end module femcod_process
