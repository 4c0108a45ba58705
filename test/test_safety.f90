!> Results are never lost, mixed or destroyed (cli/femcod_run): stop signals write a
!> checkpoint that --restart continues to the same bytes, a prefix is locked while a run
!> writes it, --force replaces a set as a whole, a checkpoint or a finished run of other
!> inputs is not overwritten or reused silently, batch runs keep their outputs apart.
!> Every run here is this test program run as femcod in its own process.
module test_safety
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: write_deck
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem
   use femcod_process, only: process_id, host_name, process_alive
   use femcod_files, only: acquire_lock, release_lock
   use femcod_strings, only: int_str
   use femcod_output_guard, only: written_by_femcod, OUTPUT_RESULT, OUTPUT_DECK, OUTPUT_WISDOM
   use femcod_solver_options, only: contact_options, &
      BOUNDARY_PERIODIC
   use femcod_incremental_state, only: incremental_state
   use femcod_checkpoint, only: write_checkpoint, read_checkpoint
   use femcod_deck, only: read_deck
   use test_support, only: scratch_path, read_text, file_exists, write_text, contains_text
   use test_results, only: self_command
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_safety

contains

   subroutine collect_safety(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("SIGTERM: exit 143, a checkpoint, no result; --restart gives the same bytes", test_sigterm), &
         new_unittest("SIGTERM to cg: the loads solved kept as a partial set, --restart completes it", &
            test_sigterm_partial), &
         new_unittest("a prefix is locked: a live holder refuses the run, a dead one is taken over", test_lock), &
         new_unittest("a lock's holder: alive, reaped, a zombie, stopped with SIGKILL pending", test_holder_alive), &
         new_unittest("a lock appears with its line (linked in place), no name of its own left", test_lock_whole), &
         new_unittest("--force replaces the set as a whole (no stale pressure maps)", test_force_set), &
         new_unittest("a checkpoint is not overwritten without --restart or --force", test_checkpoint_kept), &
         new_unittest("--restart on finished results: nothing to do only for the same inputs", test_restart_finished), &
         new_unittest("--restart works for height-file runs", test_restart_heights), &
         new_unittest("batch: --outdir; decks that would write the same files are refused", test_batch_outputs), &
         new_unittest("a full disk (the job's file-size limit): exit 5, the cause, no file left", test_full_disk), &
         new_unittest("femcod's own files are told from a user's by their form (output guard)", test_own_files), &
         new_unittest("--force replaces femcod's deck and results; --fftw-wisdom reuses its file", test_force_own), &
         new_unittest("a checkpoint continues only the physics it was written with (whole option set)", &
            test_checkpoint_options) &
         ]
   end subroutine collect_safety

   !> A 64 x 64 rough deck that takes long enough to be stopped midway.
   subroutine make_deck(path, maxcont)
      character(len=*), intent(in) :: path
      integer, intent(in) :: maxcont
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(status_type) :: st
      spec%kind = "self-affine"
      spec%label = "safety test: self-affine 64 x 64"
      spec%matrix_file = ""
      spec%np = 64
      spec%pixel = 10
      spec%rms = 3
      spec%maxcont = maxcont
      call build_problem(spec, deck, st)
      call write_deck(path, deck, st)
   end subroutine make_deck

   !> Run femcod with `args` in a shell; its exit code.
   integer function femcod(args)
      character(len=*), intent(in) :: args
      call execute_command_line(self_command()//" "//args//" 2> "//scratch_path("safety.stderr"), exitstat=femcod)
   end function femcod

   !> Run femcod in the background and send it SIGTERM after `delay` seconds; its exit code.
   integer function femcod_terminated(args, delay)
      character(len=*), intent(in) :: args
      real(dp), intent(in) :: delay
      character(len=16) :: d
      character(len=:), allocatable :: rc, text
      integer :: ios
      write(d, '(f0.3)') delay
      rc = scratch_path("safety.rc")
      call execute_command_line("( "//self_command()//" "//args//" 2> "//scratch_path("safety.stderr")// &
         " & pid=$!; sleep "//trim(d)//"; kill -TERM $pid 2>/dev/null; wait $pid; echo $? > "//rc//" )", exitstat=ios)
      femcod_terminated = -1
      text = read_text(rc)
      read(text, *, iostat=ios) femcod_terminated
   end function femcod_terminated

   !> SIGTERM between two steps: exit 128 + 15, the state in the checkpoint, no result file,
   !> no lock, no temporary file; --restart then ends with the bytes of an uninterrupted run.
   subroutine test_sigterm(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, args
      integer(8) :: c0, c1, rate
      real(dp) :: duration
      integer :: code, k
      real(dp), parameter :: fractions(*) = [0.5_dp, 0.3_dp, 0.7_dp, 0.15_dp]
      dir = scratch_path("sigterm")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 1200)
      args = "run "//dir//"/scene.deck --loads 5e4,1e9 --quiet "
      call system_clock(c0, rate)
      code = femcod(args//"-o "//dir//"/ref")
      call system_clock(c1)
      duration = real(c1 - c0, dp)/rate
      call check(error, code, 0, "the uninterrupted run")
      if (allocated(error)) return
      ! The signal must arrive while the run solves: try a few moments.
      do k = 1, size(fractions)
         call execute_command_line("rm -f "//dir//"/ck.*")
         code = femcod_terminated(args//"-o "//dir//"/ck --checkpoint-interval 300", fractions(k)*duration)
         if (code /= 0) exit
      end do
      call check(error, code, 143, "exit 128 + SIGTERM (stderr: "//read_text(scratch_path("safety.stderr"))//")")
      if (allocated(error)) return
      call check(error, contains_text(read_text(scratch_path("safety.stderr")), "SIGTERM: stopped at step") .and. &
         contains_text(read_text(scratch_path("safety.stderr")), "continue with --restart"), &
         "what was saved is said: "//read_text(scratch_path("safety.stderr")))
      if (allocated(error)) return
      call check(error, file_exists(dir//"/ck.ckpt.h5") .and. .not. file_exists(dir//"/ck.h5") .and. &
         .not. file_exists(dir//"/ck.history.csv") .and. .not. file_exists(dir//"/ck.lock") .and. &
         .not. file_exists(dir//"/ck.ckpt.h5.part") .and. .not. file_exists(dir//"/ck.history.csv.part"), &
         "a checkpoint, and no result, lock or temporary file")
      if (allocated(error)) return
      code = femcod(args//"-o "//dir//"/ck --restart")
      call check(error, code, 0, "the restart")
      if (allocated(error)) return
      call check(error, read_text(dir//"/ck.history.csv") == read_text(dir//"/ref.history.csv") .and. &
         read_text(dir//"/ck.contacts.csv") == read_text(dir//"/ref.contacts.csv") .and. &
         read_text(dir//"/ck.loads.csv") == read_text(dir//"/ref.loads.csv"), "the same bytes as the uninterrupted run")
      if (allocated(error)) return
      call check(error, .not. file_exists(dir//"/ck.ckpt.h5"), "the checkpoint is removed at the end")
   end subroutine test_sigterm

   !> Issue 47: a cg run of 200 loads stopped by SIGTERM kept nothing (147 of 399 loads
   !> lost in the trial). Now: exit 143, the loads solved before the signal written as a
   !> partial set (each row the uninterrupted run's, to the bit: the loads are solved in
   !> order, each from the last), the summary's "stopped" says so; --restart runs it
   !> again to the uninterrupted run's bytes.
   subroutine test_sigterm_partial(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, args, loads, partial, whole
      integer(8) :: c0, c1, rate
      real(dp) :: duration
      integer :: code, k, rows
      real(dp), parameter :: fractions(*) = [0.5_dp, 0.3_dp, 0.7_dp, 0.15_dp]
      dir = scratch_path("sigterm_cg")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 1200)
      loads = "20"
      do k = 2, 200
         loads = loads//","//to_string(20*k)
      end do
      args = "run "//dir//"/scene.deck --solver cg --loads "//loads//" --quiet "
      call system_clock(c0, rate)
      code = femcod(args//"-o "//dir//"/ref")
      call system_clock(c1)
      duration = real(c1 - c0, dp)/rate
      call check(error, code, 0, "the uninterrupted run")
      if (allocated(error)) return
      do k = 1, size(fractions)
         call execute_command_line("rm -f "//dir//"/ck.*")
         code = femcod_terminated(args//"-o "//dir//"/ck", fractions(k)*duration)
         if (code /= 0 .and. file_exists(dir//"/ck.h5")) exit
      end do
      call check(error, code, 143, "exit 128 + SIGTERM (stderr: "//read_text(scratch_path("safety.stderr"))//")")
      if (allocated(error)) return
      call check(error, contains_text(read_text(scratch_path("safety.stderr")), "(a partial run)") .and. &
         contains_text(read_text(dir//"/ck.summary.json"), '"stopped": "interrupted by a stop signal: a partial run"'), &
         "the partial set is said to be one: "//read_text(scratch_path("safety.stderr")))
      if (allocated(error)) return
      partial = read_text(dir//"/ck.loads.csv")
      whole = read_text(dir//"/ref.loads.csv")
      rows = count_lines(partial)
      call check(error, rows > 1 .and. rows < count_lines(whole) .and. whole(1:len(partial)) == partial, &
         "the partial set's "//to_string(rows - 1)//" rows are the first of the uninterrupted run's")
      if (allocated(error)) return
      call check(error, .not. file_exists(dir//"/ck.lock"), "no lock left")
      if (allocated(error)) return
      code = femcod(args//"-o "//dir//"/ck --restart")
      call check(error, code, 0, "the restart")
      if (allocated(error)) return
      call check(error, read_text(dir//"/ck.loads.csv") == whole, "--restart completes it: the same bytes")
   contains
      integer function count_lines(text)
         character(len=*), intent(in) :: text
         integer :: i
         count_lines = 0
         do i = 1, len(text)
            if (text(i:i) == new_line("a")) count_lines = count_lines + 1
         end do
      end function count_lines
   end subroutine test_sigterm_partial

   subroutine test_lock(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir
      integer :: code
      dir = scratch_path("lock")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 20)
      ! This test program is alive: its lock holds.
      call write_text(dir//"/out.lock", to_string(process_id())//" "//host_name()//new_line("a"))
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out --quiet")
      call check(error, code, 5, "a live holder refuses the run")
      if (allocated(error)) return
      call check(error, contains_text(read_text(scratch_path("safety.stderr")), "another run writes these results") &
         .and. .not. file_exists(dir//"/out.h5"), "said, and nothing written")
      if (allocated(error)) return
      ! A process number beyond Linux's pid_max (4194304) never runs: taken over.
      call write_text(dir//"/out.lock", "99999999 "//host_name()//new_line("a"))
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out")
      call check(error, code, 0, "a stale lock is taken over")
      if (allocated(error)) return
      call check(error, contains_text(read_text(scratch_path("safety.stderr")), "taken over from process 99999999") &
         .and. file_exists(dir//"/out.h5") .and. .not. file_exists(dir//"/out.lock"), "said, written, released")
   end subroutine test_lock

   !> The lock is written under a name of the process's own and linked to PREFIX.lock, so
   !> it never exists without its "PID HOST" line (created empty and filled after, a run
   !> killed in between left a lock every later run refused: doc/results.md). Taken: the
   !> line names this process and host; taken again while held: refused (exit code 5,
   !> doc/results.md); either way no PREFIX.lock.PID is left; released: gone.
   subroutine test_lock_whole(error)
      type(error_type), allocatable, intent(out) :: error
      type(status_type) :: st, again
      character(len=:), allocatable :: dir, notice, mine
      dir = scratch_path("lock-whole")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      mine = dir//"/out.lock."//int_str(process_id())
      call acquire_lock(dir//"/out.lock", st, notice)
      call check(error, st%code, 0, "taken")
      if (allocated(error)) return
      call check(error, read_text(dir//"/out.lock"), to_string(process_id())//" "//host_name()//new_line("a"), &
         "the lock's line")
      if (allocated(error)) return
      call check(error, .not. file_exists(mine), "no name of its own left after taking it")
      if (allocated(error)) return
      call acquire_lock(dir//"/out.lock", again, notice)
      call check(error, again%code == 5 .and. index(again%message, "another run writes these results") > 0, &
         "taken again while held: refused")
      if (allocated(error)) return
      call check(error, .not. file_exists(mine), "no name of its own left after a refusal")
      if (allocated(error)) return
      call release_lock(dir//"/out.lock")
      call check(error, .not. file_exists(dir//"/out.lock"), "released")
   end subroutine test_lock_whole

   subroutine test_force_set(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir
      integer :: code
      dir = scratch_path("force_set")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 50)
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out --loads 100,200,300 --quiet")
      call check(error, code == 0 .and. file_exists(dir//"/out.pressure_3.svg"), "three loads")
      if (allocated(error)) return
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out --quiet --force")
      call check(error, code, 0, "replaced, no loads")
      if (allocated(error)) return
      call check(error, .not. file_exists(dir//"/out.pressure_1.svg") .and. .not. file_exists(dir// &
         "/out.pressure_3.svg") .and. .not. file_exists(dir//"/out.loads.csv"), "no file of the earlier set is left")
   end subroutine test_force_set

   subroutine test_checkpoint_kept(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir
      integer :: code
      dir = scratch_path("ckpt_kept")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 1200)
      code = femcod_terminated("run "//dir//"/scene.deck -o "//dir//"/out --quiet", 0.3_dp)
      if (code == 0) then
         ! The run was faster than the signal: make a checkpoint-like file to protect.
         call execute_command_line("cp "//dir//"/out.h5 "//dir//"/out.ckpt.h5")
      end if
      call check(error, file_exists(dir//"/out.ckpt.h5"), "a checkpoint")
      if (allocated(error)) return
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out --quiet")
      call check(error, code, 5, "without --restart or --force")
      if (allocated(error)) return
      call check(error, contains_text(read_text(scratch_path("safety.stderr")), "the checkpoint of an interrupted run") &
         .and. file_exists(dir//"/out.ckpt.h5"), "said, and kept")
   end subroutine test_checkpoint_kept

   subroutine test_restart_finished(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, before
      integer :: code
      dir = scratch_path("restart_finished")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 40)
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out --loads 100 --quiet")
      call check(error, code, 0, "the run")
      if (allocated(error)) return
      before = read_text(dir//"/out.loads.csv")
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out --loads 100 --restart")
      call check(error, code == 0 .and. contains_text(read_text(scratch_path("safety.stderr")), "is complete"), &
         "the same run: complete, nothing to do")
      if (allocated(error)) return
      code = femcod("run "//dir//"/scene.deck -o "//dir//"/out --loads 200 --restart --quiet")
      call check(error, code, 5, "other loads: refused")
      if (allocated(error)) return
      call check(error, contains_text(read_text(scratch_path("safety.stderr")), "other inputs or options") .and. &
         read_text(dir//"/out.loads.csv") == before, "said, and the results kept")
   end subroutine test_restart_finished

   !> A height-file run stopped by SIGTERM continues with --restart (the scene's label no
   !> longer holds the operational options, so the checkpoint matches).
   subroutine test_restart_heights(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, heights, args
      integer :: code, i, j
      character(len=*), parameter :: nl = new_line("a")
      dir = scratch_path("restart_heights")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      heights = ""
      do i = 1, 64
         do j = 1, 64
            heights = heights//to_string(modulo(i*37 + j*101 + i*j*7, 97))//" "
         end do
         heights = heights//nl
      end do
      call write_text(dir//"/scan.txt", heights)
      args = "run --lower "//dir//"/scan.txt --pixel 5 --maxcont 1500 --quiet -o "//dir//"/out "
      code = femcod_terminated(args, 0.2_dp)
      if (code /= 0) then
         ! Stopped: with a checkpoint, or before the first step with nothing to keep.
         call check(error, code == 143 .and. (file_exists(dir//"/out.ckpt.h5") .or. &
            contains_text(read_text(scratch_path("safety.stderr")), "nothing was written")), &
            "stopped with a checkpoint, or before anything was solved: "//read_text(scratch_path("safety.stderr")))
         if (allocated(error)) return
      end if
      code = femcod(args//"--restart")
      call check(error, code, 0, "--restart of a height-file run: "//read_text(scratch_path("safety.stderr")))
   end subroutine test_restart_heights

   subroutine test_batch_outputs(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir
      integer :: code
      dir = scratch_path("batch_outputs")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir//"/a "//dir//"/b")
      call make_deck(dir//"/a/scene.deck", 20)
      call make_deck(dir//"/b/scene.deck", 20)
      call make_deck(dir//"/b/other.deck", 20)
      code = femcod("run "//dir//"/a/scene.deck "//dir//"/b/scene.deck --quiet")
      call check(error, code == 2 .and. contains_text(read_text(scratch_path("safety.stderr")), "would both write"), &
         "two decks named alike: refused")
      if (allocated(error)) return
      code = femcod("run "//dir//"/b/scene.deck "//dir//"/b/./scene.deck --quiet")
      call check(error, code == 2 .and. contains_text(read_text(scratch_path("safety.stderr")), "given twice"), &
         "one deck by two paths: refused")
      if (allocated(error)) return
      code = femcod("run "//dir//"/b/scene.deck -o "//dir//"/b --quiet")
      call check(error, code == 2 .and. contains_text(read_text(scratch_path("safety.stderr")), "not a directory"), &
         "-o naming a directory: refused")
      if (allocated(error)) return
      code = femcod("run "//dir//"/a/scene.deck "//dir//"/b/other.deck --outdir "//dir//"/results/x --quiet")
      call check(error, code == 0 .and. file_exists(dir//"/results/x/scene.h5") .and. &
         file_exists(dir//"/results/x/other.h5"), "--outdir made and filled")
   end subroutine test_batch_outputs

   !> A write that fails for want of space. A real full disk needs a small file system
   !> (root); the file-size limit of `ulimit -f` fails writes with EFBIG the same way
   !> (femcod turns SIGXFSZ off). 32 blocks of 512 bytes (dash, /bin/sh on Debian) or
   !> 1 KiB (bash): 16 or 32 KiB, below the HDF5 file of this run (about 70 KiB).
   !> Before femcod wrote through C's stdio, gfortran's WRITE reported success on a
   !> full disk and the files were cut short with exit 0; HDF5 1.10 crashed at exit.
   subroutine test_full_disk(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, listing
      integer :: code
      dir = scratch_path("full_disk")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir//"/out")
      call make_deck(dir//"/scene.deck", 40)
      call execute_command_line("ulimit -f 32 && "//self_command()//" run "//dir//"/scene.deck -o "//dir// &
         "/out/r --loads 100,200 --quiet 2> "//scratch_path("safety.stderr"), exitstat=code)
      call check(error, code, 5, "exit 5 (stderr: "//read_text(scratch_path("safety.stderr"))//")")
      if (allocated(error)) return
      call check(error, contains_text(read_text(scratch_path("safety.stderr")), "(File too large)"), &
         "the cause is said: "//read_text(scratch_path("safety.stderr")))
      if (allocated(error)) return
      call execute_command_line("ls -A "//dir//"/out > "//dir//"/listing")
      listing = read_text(dir//"/listing")
      call check(error, len(listing) == 0, "no file left: "//listing)
   end subroutine test_full_disk
   !> Files whose origin the test knows: femcod wrote the result set, the deck and the
   !> wisdom; the test wrote a user's notes, a height matrix, a header-less table and an
   !> HDF5 height file (test/corpus). Each is recognised for what it is.
   subroutine test_own_files(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir
      character(len=*), parameter :: set(*) = [character(len=20) :: ".h5", ".xdmf", ".history.csv", ".contacts.csv", &
         ".loads.csv", ".summary.json", ".load_approach.svg", ".area_load.svg", ".pressure_1.svg"]
      integer :: k
      dir = scratch_path("own_files")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 20)
      call check(error, femcod("run "//dir//"/scene.deck --solver cg --loads 100 --quiet -o "//dir//"/r "// &
         "--fftw-wisdom "//dir//"/w"), 0, "the run")
      if (allocated(error)) return
      do k = 1, size(set)
         call check(error, written_by_femcod(dir//"/r"//trim(set(k)), OUTPUT_RESULT), "femcod wrote r"//trim(set(k)))
         if (allocated(error)) return
      end do
      call check(error, written_by_femcod("doc/verification.md", OUTPUT_RESULT), "femcod verify wrote its report")
      if (allocated(error)) return
      call check(error, .not. written_by_femcod("README.md", OUTPUT_RESULT), "a page a person wrote")
      if (allocated(error)) return
      call check(error, written_by_femcod(dir//"/scene.deck", OUTPUT_DECK), "femcod wrote the deck")
      if (allocated(error)) return
      call check(error, written_by_femcod(dir//"/w", OUTPUT_WISDOM) .and. &
         written_by_femcod(dir//"/w.float32", OUTPUT_WISDOM), "femcod wrote the wisdom (double and float32)")
      if (allocated(error)) return
      call write_text(dir//"/notes.csv", "My notes on the scan"//new_line("a"))
      call write_text(dir//"/numbers.csv", "1,2,3"//new_line("a")//"4,5,6"//new_line("a"))
      call write_text(dir//"/empty.svg", "")
      call execute_command_line("cp test/corpus/63_heights.h5 "//dir//"/heights.h5")
      call check(error, .not. written_by_femcod(dir//"/notes.csv", OUTPUT_RESULT) .and. &
         .not. written_by_femcod(dir//"/numbers.csv", OUTPUT_RESULT) .and. &
         .not. written_by_femcod(dir//"/empty.svg", OUTPUT_RESULT) .and. &
         .not. written_by_femcod(dir//"/heights.h5", OUTPUT_RESULT), "a user's table, figure and HDF5 file")
      if (allocated(error)) return
      call check(error, .not. written_by_femcod(dir//"/numbers.csv", OUTPUT_DECK) .and. &
         .not. written_by_femcod(dir//"/r.h5", OUTPUT_DECK) .and. &
         .not. written_by_femcod("test/corpus/40_square_matrix.txt", OUTPUT_DECK), "not decks")
      if (allocated(error)) return
      call check(error, .not. written_by_femcod(dir//"/scene.deck", OUTPUT_WISDOM) .and. &
         .not. written_by_femcod(dir//"/r.h5", OUTPUT_WISDOM), "not wisdom")
   end subroutine test_own_files

   !> The other side of the corpus' refusals: what femcod wrote is replaced with --force,
   !> and the wisdom file is read and brought up to date without it.
   subroutine test_force_own(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, before
      dir = scratch_path("force_own")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call check(error, femcod("mkdeck flat --np 4 --pixel 1 -o "//dir//"/a.deck"), 0, "mkdeck")
      if (allocated(error)) return
      before = read_text(dir//"/a.deck")
      call check(error, femcod("mkdeck flat --np 4 --pixel 2 -o "//dir//"/a.deck"), 5, "mkdeck without --force")
      if (allocated(error)) return
      call check(error, read_text(dir//"/a.deck") == before, "the deck is kept")
      if (allocated(error)) return
      call check(error, femcod("mkdeck flat --np 4 --pixel 2 -o "//dir//"/a.deck --force"), 0, "mkdeck --force")
      if (allocated(error)) return
      call check(error, contains_text(read_text(dir//"/a.deck"), "4 2 16"), "the deck is replaced: "// &
         read_text(dir//"/a.deck"))
      if (allocated(error)) return
      call make_deck(dir//"/scene.deck", 20)
      call check(error, femcod("run "//dir//"/scene.deck --solver cg --loads 100 --quiet -o "//dir//"/r "// &
         "--fftw-wisdom "//dir//"/w"), 0, "a run that writes the wisdom")
      if (allocated(error)) return
      call check(error, femcod("run "//dir//"/scene.deck --solver cg --loads 100 --quiet -o "//dir//"/r --force "// &
         "--fftw-wisdom "//dir//"/w"), 0, "a second run reads and updates it, and --force replaces its results")
      if (allocated(error)) return
      call check(error, contains_text(read_text(dir//"/w"), "(fftw-3"), "the wisdom is FFTW's")
   end subroutine test_force_own
   !> A checkpoint of a plastic run (--plastic --hardness 4) used to be accepted by a run
   !> without --plastic, which then continued it as an elastic history (issue 34). The
   !> checkpoint stores the whole option set and --restart compares it whole: each option
   !> that shapes the history, changed alone, is refused with the field named (exit 3);
   !> the same options are accepted. The expected refusals follow from the options'
   !> meaning, not from the code: each changes the answer.
   subroutine test_checkpoint_options(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: problem
      type(contact_options) :: written, other
      type(incremental_state) :: state, again
      type(status_type) :: st
      character(len=:), allocatable :: dir
      integer :: k
      character(len=*), parameter :: fields(*) = [character(len=14) :: "plastic", "hardness", "boundary", &
         "loads", "approaches", "max_contacts", "final_check"]
      dir = scratch_path("checkpoint_options")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call make_deck(dir//"/scene.deck", 40)
      call read_deck(dir//"/scene.deck", problem, st)
      written%plastic = .true.
      written%hardness = 4
      written%loads = [real(dp) ::]
      written%approaches = [real(dp) ::]
      call state%init(problem, written)
      call write_checkpoint(dir//"/run.ckpt.h5", problem, written, state, st)
      call check(error, st%code, 0, "writing the checkpoint: "//st%message)
      if (allocated(error)) return
      call again%init(problem, written)
      call read_checkpoint(dir//"/run.ckpt.h5", problem, written, again, st)
      call check(error, st%code, 0, "the same options continue: "//st%message)
      if (allocated(error)) return
      do k = 1, size(fields)
         other = written
         select case (trim(fields(k)))
         case ("plastic")
            other%plastic = .false.
         case ("hardness")
            other%hardness = 5
         case ("boundary")
            other%boundary = BOUNDARY_PERIODIC
         case ("loads")
            other%loads = [100.0_dp]
         case ("approaches")
            other%approaches = [1.0_dp]
         case ("max_contacts")
            other%max_contacts = 10
         case ("final_check")
            other%final_check = .false.
         end select
         st = status_type()
         call again%init(problem, other)
         call read_checkpoint(dir//"/run.ckpt.h5", problem, other, again, st)
         call check(error, st%code, 3, trim(fields(k))//" changed: refused")
         if (allocated(error)) return
         call check(error, contains_text(st%message, trim(fields(k))//"="), trim(fields(k))// &
            " changed: the message names it: "//st%message)
         if (allocated(error)) return
      end do
   end subroutine test_checkpoint_options

   !> femcod_process' process_alive, which decides whether a lock is held: this process is
   !> alive; a process that ended and was reaped is not; a zombie (a child whose parent
   !> does not reap it) is not; a stopped process with SIGKILL pending (the state a run
   !> killed by `timeout -s KILL` can be in when the next one looks) is not, while the
   !> same stopped process without it is. Each process is made by the shell here.
   subroutine test_holder_alive(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: file
      integer :: pid, ios, unit
      file = scratch_path("holder.pid")
      call check(error, process_alive(process_id()), "this process")
      if (allocated(error)) return
      call execute_command_line("sh -c 'echo $$ > "//file//"'")
      call check(error, .not. process_alive(pid_in(file)), "a process that ended")
      if (allocated(error)) return
      ! A zombie: the inner sleep ends at once; its parent, exec'ed into sleep 3, never
      ! reaps it.
      call execute_command_line("sh -c '(sleep 0 & echo $! > "//file//"; exec sleep 3)' > /dev/null 2>&1 &")
      call execute_command_line("sleep 1")
      pid = pid_in(file)
      call check(error, pid > 0 .and. .not. process_alive(pid), "a zombie ("//to_string(pid)//")")
      if (allocated(error)) return
      ! Stopped, alive; stopped with SIGKILL sent (pending until it is scheduled), dying.
      call execute_command_line("sh -c 'sleep 30 & echo $! > "//file//"' && kill -STOP $(cat "//file//")")
      pid = pid_in(file)
      call check(error, pid > 0 .and. process_alive(pid), "a stopped process")
      if (allocated(error)) return
      call execute_command_line("kill -KILL "//to_string(pid))
      call check(error, .not. process_alive(pid), "a process with SIGKILL sent")
   contains
      integer function pid_in(path) result(value)
         character(len=*), intent(in) :: path
         value = -1
         open(newunit=unit, file=path, action="read", status="old", iostat=ios)
         if (ios /= 0) return
         read(unit, *, iostat=ios) value
         close(unit)
      end function pid_in
   end subroutine test_holder_alive
end module test_safety
