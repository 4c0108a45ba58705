!> `femcod run`: the contact history of decks (or of a pair of height files), each
!> solved by the solver the options name and written as one result set (PREFIX.h5,
!> .xdmf, the CSV files and the figures; doc/results.md), with a summary.
!>
!> The path of one run: the arguments are parsed against the option table (run_table)
!> into run_settings; each deck is read (or the scene built from its height files) into
!> a contact_problem; solvers/femcod_solver solves it, telling a run_observer of its
!> progress and handing it checkpoints; the maps of the reached loads are computed and
!> io/femcod_results writes the set.
module femcod_run
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp, i8
   use femcod_memory, only: available_memory, resident_bytes
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_IO, STATUS_INTERRUPTED
   use femcod_strings, only: string_type, int_str, format_real, append_string, count_text, json_string
   use femcod_files, only: remove_file, path_exists, path_is_directory, canonical_path, acquire_lock, release_lock, &
      make_directories, write_file, temporary_name
   use femcod_process, only: catch_stop_signals, stop_signal, signal_name, host_name, &
      openmp_threads, wait_policy_text, local_time_iso
   use femcod_sha256, only: sha256_hex, file_digest, file_sha256_start, file_sha256_finish
   use femcod_clock, only: wall_clock
   use femcod_problem, only: contact_problem
   use femcod_deck, only: read_deck
   use femcod_heights, only: load_scene, height_file_path, looks_like_height_matrix
   use femcod_contact_result, only: contact_result, STOP_INTERRUPTED
   use femcod_solver_options, only: contact_options, requested_states, history_options, SOLVER_CG, BOUNDARY_PERIODIC
   use femcod_cerruti, only: second_dundurs_constant
   use femcod_state_record, only: run_info_for
   use femcod_incremental_state, only: incremental_state
   use femcod_solver, only: solve_contact, model_notes, run_warnings
   use femcod_maps, only: load_maps, state_maps
   use femcod_checkpoint, only: read_checkpoint
   use femcod_wisdom, only: load_wisdom, save_wisdom
   use femcod_output_guard, only: guard_outputs, OUTPUT_WISDOM, OUTPUT_RESULT
   use femcod_results, only: write_results, run_info, result_files, stored_fingerprint, pressure_figure_wanted, &
      MAP_FIGURES, figure_name
   use femcod_results_hdf5, only: start_result_file
   use femcod_about, only: FEMCOD_VERSION
   use femcod_help, only: help_requested
   use femcod_run_options, only: run_table, run_settings, parse_run_arguments, run_help, deck_label
   use femcod_run_observer, only: run_observer
   use femcod_run_summary, only: print_summary
   implicit none
   private
   public :: run_command

   !> Appended to the fingerprint of a partial run (a stop signal between two requested
   !> states of cg or legacy): --restart runs it again rather than calling it complete.
   character(len=*), parameter :: PARTIAL_MARK = " (partial)"

contains

   !> `femcod run ARGS`: `code` is the exit code (of the first failing deck in a batch;
   !> 128 + the signal's number after SIGTERM, SIGINT or SIGUSR1).
   subroutine run_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(run_settings) :: settings
      type(status_type) :: status
      type(string_type), allocatable :: failed(:)
      character(len=:), allocatable :: message
      integer :: d, rc, k
      code = 0
      if (help_requested(args)) then
         call run_help()
         return
      end if
      call parse_run_arguments(args, settings, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod run: "//status%message//" (femcod run --help)"
         code = status%code
         return
      end if
      if (len(settings%wisdom) > 0) call check_wisdom_file(settings, status)
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod run: "//status%message
         code = status%code
         return
      end if
      if (settings%outdir /= "") then
         call make_directories(settings%outdir, status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod: "//status%message
            code = status%code
            return
         end if
      end if
      ! -o out/circle in a fresh directory: out/ is made, as --outdir makes its DIR.
      do d = 1, size(settings%prefixes)
         k = index(settings%prefixes(d)%s, "/", back=.true.)
         if (k <= 1) cycle
         if (path_is_directory(settings%prefixes(d)%s(1:k - 1))) cycle
         call make_directories(settings%prefixes(d)%s(1:k - 1), status)
         if (status%code /= 0) then
            write(error_unit, '(a)') "femcod: "//status%message
            code = status%code
            return
         end if
      end do
      ! A batch system's stop signals end the run between two steps, with a checkpoint.
      call catch_stop_signals()
      ! Batch: every deck runs; a failed deck is reported and the others go on.
      allocate(failed(0))
      do d = 1, size(settings%decks)
         call run_one(settings%decks(d)%s, settings%prefixes(d)%s, settings, rc, message)
         if (size(settings%decks) > 1) call record_batch_outcome(settings%decks(d)%s, settings%prefixes(d)%s, rc, message)
         if (rc /= 0) then
            call append_string(failed, settings%decks(d)%s)
            if (code == 0) code = rc
         end if
         ! A signal stops the batch. One that arrives after the last deck's results are
         ! written leaves nothing undone: the exit code stays that of the work.
         if (stop_signal() /= 0 .and. d < size(settings%decks)) then
            code = 128 + stop_signal()
            write(error_unit, '(a)') "femcod: "//signal_name(stop_signal())// &
               ": the batch stops; "//int_str(size(settings%decks) - d)// &
               trim(merge(" deck not run ", " decks not run", size(settings%decks) - d == 1))
            exit
         end if
      end do
      if (size(settings%decks) > 1) then
         write(output_unit, '(a)') "femcod run: "//int_str(size(settings%decks))//" decks, "//int_str(size(failed))// &
            " failed"
         do d = 1, size(failed)
            write(output_unit, '(a)') "  failed: "//failed(d)%s
         end do
      end if
   end subroutine run_command

   !> One deck ("" for the height files): read, lock its prefix, solve, write, report.
   !> `rc` is its exit code.
   subroutine run_one(deck_path, prefix, settings, rc, message)
      character(len=*), intent(in) :: deck_path, prefix
      type(run_settings), intent(in) :: settings
      integer, intent(out) :: rc
      !> Why the deck failed ("" when it did not).
      character(len=:), allocatable, intent(out) :: message
      type(contact_problem) :: problem
      type(status_type) :: st
      type(string_type), allocatable :: inputs(:), warnings(:), files(:)
      type(file_digest), allocatable :: pending(:)
      character(len=:), allocatable :: notice, hex
      real(dp) :: t0, read_seconds
      integer :: k
      rc = 0
      message = ""
      call wall_clock(t0)
      if (deck_path == "") then
         call load_scene(settings%scene, problem, st, inputs, warnings)
         do k = 1, size(warnings)
            write(error_unit, '(a)') "femcod: warning: "//warnings(k)%s
         end do
         allocate(files(0))
         if (st%code == 0) then
            call append_string(files, height_file_path(settings%scene%matrix_file))
            if (settings%scene%second_file /= "") call append_string(files, height_file_path(settings%scene%second_file))
         end if
         allocate(pending(size(files)))
         do k = 1, size(files)
            call file_sha256_start(files(k)%s, pending(k))
         end do
      else
         ! The deck's digest is taken while it is read.
         allocate(pending(1))
         call file_sha256_start(deck_path, pending(1))
         call read_deck(deck_path, problem, st)
         if (st%code /= 0 .and. looks_like_height_matrix(deck_path)) then
            st%code = STATUS_USAGE
            st%message = deck_path//" reads as a matrix of heights, not as a deck: run it with --lower "// &
               deck_path//" --pixel D ("//st%message//")"
         end if
         inputs = [string_type(deck_path//": femcod deck")]
         files = [string_type(deck_path)]
      end if
      call wall_clock(read_seconds)
      read_seconds = read_seconds - t0
      ! No output may ever replace an input.
      if (st%code == 0) call refuse_input_as_output(prefix, requested_states(settings%solve), files, st)
      if (st%code == 0) then
         call acquire_lock(prefix//".lock", st, notice)
         if (notice /= "" .and. .not. settings%quiet) write(error_unit, '(a)') "femcod: "//notice
         if (st%code == 0) then
            call run_locked(deck_path, prefix, settings, problem, inputs, files, pending, read_seconds, st)
            ! PREFIX.h5's temporary, begun before a cg solve (the heights, the solved
            ! states' gap maps), goes with a run that ends without its results.
            if (st%code /= 0) call remove_file(temporary_name(prefix//".h5"))
            call release_lock(prefix//".lock")
         end if
      end if
      ! Digests not collected (a run refused before it started) are waited for here.
      do k = 1, size(pending)
         hex = file_sha256_finish(pending(k))
      end do
      if (st%code /= 0) then
         message = st%message
         if (st%code == STATUS_INTERRUPTED) then
            write(error_unit, '(a)') "femcod: "//signal_name(stop_signal())//": "//st%message
            rc = 128 + stop_signal()
         else
            write(error_unit, '(a)') "femcod: "//st%message
            rc = st%code
         end if
      end if
   end subroutine run_one

   !> A batch deck's failure as PREFIX.failed.json (deck, exit code, message: what
   !> `femcod report DIR` lists), written atomically; a deck that succeeds removes the
   !> record an earlier batch left. A record that cannot be written is said, not fatal.
   subroutine record_batch_outcome(deck_path, prefix, rc, message)
      character(len=*), intent(in) :: deck_path, prefix, message
      integer, intent(in) :: rc
      type(status_type) :: st
      character(len=1), parameter :: nl = new_line("a")
      if (rc == 0) then
         call remove_file(prefix//".failed.json")
         return
      end if
      call write_file(prefix//".failed.json", "{"//nl//'  "deck": '//json_string(deck_path)//","//nl// &
         '  "results": '//json_string(prefix)//","//nl//'  "exit_code": '//int_str(rc)//","//nl// &
         '  "message": '//json_string(message)//","//nl//'  "femcod_version": '//json_string(FEMCOD_VERSION)//","// &
         nl//'  "finished": '//json_string(local_time_iso())//nl//"}"//nl, st)
      if (st%code /= 0) write(error_unit, '(a)') "femcod: warning: the batch's failure record: "//st%message
   end subroutine record_batch_outcome

   !> --fftw-wisdom FILE, before any deck is read: FILE and FILE.float32 are neither an
   !> input nor a result file of this run, and each that exists is FFTW wisdom (it is
   !> then read and brought up to date without --force: that is what the option is for);
   !> a file that is not wisdom is refused and left as it is.
   subroutine check_wisdom_file(settings, st)
      type(run_settings), intent(in) :: settings
      type(status_type), intent(inout) :: st
      type(string_type), allocatable :: inputs(:), outputs(:)
      type(string_type) :: wisdom(2)
      integer :: d, m, w
      allocate(inputs(0), outputs(0))
      do d = 1, size(settings%decks)
         if (settings%decks(d)%s /= "") then
            call append_string(inputs, settings%decks(d)%s)
         else
            call append_string(inputs, height_file_path(settings%scene%matrix_file))
            if (settings%scene%second_file /= "") &
               call append_string(inputs, height_file_path(settings%scene%second_file))
         end if
         outputs = [outputs, result_files(settings%prefixes(d)%s, requested_states(settings%solve)), &
            string_type(settings%prefixes(d)%s//".ckpt.h5"), string_type(settings%prefixes(d)%s//".lock")]
      end do
      wisdom(1)%s = settings%wisdom
      wisdom(2)%s = settings%wisdom//".float32"
      do w = 1, size(wisdom)
         do m = 1, size(outputs)
            if (canonical_path(wisdom(w)%s) == canonical_path(outputs(m)%s)) then
               call set_error(st, STATUS_USAGE, "--fftw-wisdom: "//wisdom(w)%s//" is also a result file of this "// &
                  "run; give the wisdom a name of its own")
               return
            end if
         end do
      end do
      call guard_outputs(wisdom, inputs, .true., OUTPUT_WISDOM, st)
      if (st%code /= 0) st%message = "--fftw-wisdom: "//st%message
   end subroutine check_wisdom_file

   !> What exists under `prefix` before a run: with --restart, a complete set of the same
   !> inputs and options (`complete`: nothing to do) or of others (refused); a checkpoint
   !> without --restart or --force (refused); existing results without --force (refused);
   !> and with --force (or as a restart's leftovers) only files femcod wrote are replaced.
   subroutine check_existing(deck_path, prefix, settings, fingerprint, have_checkpoint, complete, st)
      character(len=*), intent(in) :: deck_path, prefix, fingerprint
      type(run_settings), intent(in) :: settings
      logical, intent(out) :: have_checkpoint, complete
      type(status_type), intent(inout) :: st
      character(len=:), allocatable :: stored
      type(string_type), allocatable :: names(:), none(:), checkpoint(:)
      logical :: partial
      complete = .false.
      have_checkpoint = path_exists(prefix//".ckpt.h5")
      ! With --restart, result files are leftovers of the interrupted run while its
      ! checkpoint exists, or while PREFIX.h5 (renamed last) does not. A complete set
      ! without a checkpoint means the run had finished: nothing to do, if it is the
      ! run of these inputs and options.
      partial = .false.
      if (settings%restart .and. .not. settings%force .and. .not. have_checkpoint .and. &
         path_exists(prefix//".h5")) then
         stored = stored_fingerprint(prefix//".h5")
         ! The partial set of an interrupted cg or legacy run: --restart runs it again.
         partial = stored == fingerprint//PARTIAL_MARK
         if (stored == fingerprint) then
            if (.not. settings%quiet) write(error_unit, '(a)') "femcod: "//prefix//".h5: the run of "// &
               deck_label(deck_path)//" is complete; nothing to restart"
            complete = .true.
            return
         end if
         if (.not. partial) then
            call set_error(st, STATUS_IO, prefix//".h5 holds the results of other inputs or options; "// &
               "--force replaces them, or give another -o")
            return
         end if
      end if
      if (have_checkpoint .and. .not. settings%restart .and. .not. settings%force) then
         call set_error(st, STATUS_IO, prefix//".ckpt.h5: the checkpoint of an interrupted run; continue it "// &
            "with --restart, or start afresh with --force")
         return
      end if
      call check_writable(prefix, st)
      if (st%code == 0 .and. .not. settings%force) then
         if (.not. (settings%restart .and. (have_checkpoint .or. partial .or. .not. path_exists(prefix//".h5")))) &
            call refuse_overwrite(prefix, requested_states(settings%solve), st)
      end if
      ! What is replaced (with --force, or as a restart's leftovers) must be femcod's; a
      ! checkpoint that --restart continues is checked whole by read_checkpoint.
      ! (Named arrays, not constructors in the call: gfortran's temporaries of derived types
      ! with allocatable components have corrupted the heap here, femcod-mpi 2026-11-26.)
      allocate(none(0), checkpoint(1))
      checkpoint(1)%s = prefix//".ckpt.h5"
      names = result_files(prefix, requested_states(settings%solve))
      if (st%code == 0) call guard_outputs(names, none, .true., OUTPUT_RESULT, st)
      if (st%code == 0 .and. .not. settings%restart) call guard_outputs(checkpoint, none, .true., OUTPUT_RESULT, st)
   end subroutine check_existing

   !> The result files of `prefix` (and its checkpoint and lock) may not be one of the
   !> input files, with or without --force.
   subroutine refuse_input_as_output(prefix, nloads, inputs, st)
      character(len=*), intent(in) :: prefix
      integer, intent(in) :: nloads
      type(string_type), intent(in) :: inputs(:)
      type(status_type), intent(inout) :: st
      type(string_type), allocatable :: names(:)
      integer :: m, i
      names = [result_files(prefix, nloads), string_type(prefix//".ckpt.h5"), string_type(prefix//".lock")]
      do m = 1, size(names)
         do i = 1, size(inputs)
            if (canonical_path(names(m)%s) == canonical_path(inputs(i)%s)) then
               call set_error(st, STATUS_USAGE, names(m)%s//" would replace the input "//inputs(i)%s// &
                  ": give another -o PREFIX")
               return
            end if
         end do
      end do
   end subroutine refuse_input_as_output

   !> A deck with its prefix locked: the checks of existing files, the solve, the results.
   subroutine run_locked(deck_path, prefix, settings, problem, inputs, files, pending, read_seconds, st)
      character(len=*), intent(in) :: deck_path, prefix
      type(run_settings), intent(in) :: settings
      type(contact_problem), intent(inout) :: problem
      type(string_type), intent(in) :: inputs(:), files(:)
      !> The input files' digests, started while they were read (file_sha256_start).
      type(file_digest), intent(inout) :: pending(:)
      !> Wall seconds of reading the inputs.
      real(dp), intent(in) :: read_seconds
      type(status_type), intent(inout) :: st
      type(contact_result) :: res
      type(run_observer) :: observer
      type(incremental_state) :: resume
      type(state_maps), allocatable :: maps(:)
      type(run_info) :: info
      character(len=:), allocatable :: fingerprint, started
      type(string_type), allocatable :: digests(:), warnings(:)
      logical :: resuming, ok, have_checkpoint, complete, interrupted, file_started
      type(status_type) :: stopped
      type(contact_options) :: solve_options
      integer(i8) :: held
      real(dp) :: t0, t1, digest_seconds
      integer :: k
      associate(options => settings%solve)
         ! Every input file's SHA-256, once: for /run and for the fingerprint.
         call wall_clock(t0)
         call input_digests(files, pending, digests)
         call wall_clock(t1)
         digest_seconds = t1 - t0
         fingerprint = run_fingerprint(problem, options, digests)
         call check_existing(deck_path, prefix, settings, fingerprint, have_checkpoint, complete, st)
         if (st%code /= 0 .or. complete) return
         call observer%configure(prefix, problem, options, settings%quiet)
         resuming = .false.
         if (settings%restart) then
            if (have_checkpoint) then
               call resume%init(problem, options)
               call read_checkpoint(observer%checkpoint_path, problem, options, resume, st)
               if (st%code == 0) call resume%rebuild(st)
               if (st%code /= 0 .and. index(st%message, observer%checkpoint_path) == 0) &
                  st%message = observer%checkpoint_path//": checkpoint refused: "//st%message
               if (st%code /= 0) return
               resuming = .true.
               if (.not. settings%quiet) write(error_unit, '(a)') "femcod: resuming "// &
                  deck_label(deck_path)//" from "//observer%checkpoint_path//" at step "//int_str(resume%step)//" ("// &
                  int_str(resume%n)//" contacts)"
            else if (.not. settings%quiet) then
               write(error_unit, '(a)') "femcod: no checkpoint "//observer%checkpoint_path//": starting "// &
                  deck_label(deck_path)//" from the beginning"
            end if
         else if (have_checkpoint) then
            ! --force: the old checkpoint is not this run's.
            call remove_file(prefix//".ckpt.h5")
         end if
         if (options%solver == SOLVER_CG .and. len(settings%wisdom) > 0) call load_wisdom(settings%wisdom, ok)
         started = local_time_iso()
         ! The solvers check their storage against what this run may still take; the
         ! summary's estimate is what the run holds now plus that storage.
         solve_options = options
         ! What the summary says of the scene and the surface's slope, while the heights
         ! are here: a cg solve frees them once its grid holds the initial gaps, after they
         ! went into PREFIX.h5's temporary (16 bytes a pixel less through the solve).
         info = run_info_for(problem, options)
         info%scene = model_notes(problem, options)
         file_started = options%solver == SOLVER_CG
         if (file_started) then
            call start_result_file(observer%stream_path, problem, st)
            if (st%code /= 0) return
            observer%stream_started = .true.
            solve_options%release_heights = .true.
            solve_options%states_streamed = .true.
         end if
         held = resident_bytes()
         solve_options%memory_available = available_memory()
         if (resuming) then
            call solve_contact(problem, solve_options, res, st, observer, resume)
         else
            call solve_contact(problem, solve_options, res, st, observer)
         end if
         ! The heights the solve freed (two NP x NP maps of doubles) are not held during it.
         if (solve_options%release_heights) held = held - 16*int(problem%np, i8)**2
         if (res%estimated_peak_bytes > 0) res%estimated_peak_bytes = res%estimated_peak_bytes + held
         interrupted = st%code == STATUS_INTERRUPTED
         if (interrupted) then
            if (path_exists(observer%checkpoint_path) .and. observer%stored) then
               st%message = st%message//"; the state is in "//observer%checkpoint_path//" (continue with --restart)"
               return
            else if (res%stop_reason /= STOP_INTERRUPTED .or. .not. any(res%states%reached)) then
               st%message = st%message//"; nothing was written"
               return
            end if
            ! The requested states finished before the signal are written, as a partial run.
            stopped = st
            st = status_type()
         end if
         if (st%code == 0 .and. options%solver == SOLVER_CG .and. len(settings%wisdom) > 0) &
            call save_wisdom(settings%wisdom, st)
         if (st%code /= 0) return
         info%version = FEMCOD_VERSION
         info%beta = second_dundurs_constant(problem%young(1:2), problem%poisson(1:2))
         info%options = settings%command_line
         info%figures = settings%figures
         info%command_line = "femcod run "//settings%command_line
         info%host = host_name()
         info%threads = openmp_threads()
         info%wait_policy = wait_policy_text()
         info%started = started
         info%finished = local_time_iso()
         info%inputs = inputs
         info%fingerprint = fingerprint
         ! A partial run is not the run asked for: --restart runs it again.
         if (interrupted) info%fingerprint = fingerprint//PARTIAL_MARK
         info%digests = digests
         info%read_seconds = read_seconds
         info%digest_seconds = digest_seconds
         call wall_clock(t0)
         if (allocated(observer%gap_in_file)) then
            call load_maps(problem, res%states, maps, options%boundary == BOUNDARY_PERIODIC, observer%gap_in_file)
         else
            call load_maps(problem, res%states, maps, options%boundary == BOUNDARY_PERIODIC)
         end if
         call wall_clock(t1)
         info%maps_seconds = t1 - t0
         warnings = run_warnings(options, res)
         info%warnings = warnings
         call write_results(prefix, problem, res, maps, info, st, file_started)
         if (st%code /= 0) return
         ! The set is replaced as a whole: what an earlier run left beside it goes, and the
         ! checkpoint has served its purpose.
         call remove_stale_results(prefix, res, settings%figures)
         do k = 1, size(warnings)
            write(error_unit, '(a)') "femcod: warning: "//warnings(k)%s
         end do
         if (.not. settings%quiet) call print_summary(deck_path, prefix, problem, options, res, maps)
         if (interrupted) then
            st = stopped
            st%message = st%message//"; the "//count_text(count(res%states%reached), "requested state")// &
               " finished before it are in "//prefix//".h5 and its companions (a partial run)"
         end if
      end associate
   end subroutine run_locked

   !> Remove what an earlier run of this prefix left beside the new set: pressure maps this
   !> run did not write (unreached states, --figures) or of loads beyond the new ones, a
   !> loads file when none were asked, the checkpoint.
   subroutine remove_stale_results(prefix, res, figures)
      character(len=*), intent(in) :: prefix
      type(contact_result), intent(in) :: res
      character(len=*), intent(in) :: figures
      integer :: k, m, nloads
      nloads = 0
      if (allocated(res%states)) nloads = size(res%states)
      ! The figures this run did not write (an unreached state, --figures), and those of
      ! states beyond its own.
      do k = 1, nloads
         if (pressure_figure_wanted(res, k, figures)) then
            ! The kinds this run has not (an earlier run's plastic or tangential maps).
            if (.not. allocated(res%states(k)%plastic)) call remove_file(figure_name(prefix, "plastic", k))
            if (.not. allocated(res%states(k)%stick)) call remove_file(figure_name(prefix, "stick_slip", k))
         else
            do m = 1, size(MAP_FIGURES)
               call remove_file(figure_name(prefix, MAP_FIGURES(m), k))
            end do
         end if
      end do
      k = nloads + 1
      do while (any([(path_exists(figure_name(prefix, MAP_FIGURES(m), k)), m = 1, size(MAP_FIGURES))]))
         do m = 1, size(MAP_FIGURES)
            call remove_file(figure_name(prefix, MAP_FIGURES(m), k))
         end do
         k = k + 1
      end do
      if (nloads == 0) call remove_file(prefix//".loads.csv")
      call remove_file(prefix//".ckpt.h5")
      call remove_file(prefix//".ckpt.h5.part")
   end subroutine remove_stale_results

   !> SHA-256 of what decides a run's results: the problem's label, grid and materials,
   !> the options that shape the results, and the SHA-256 of every input file (which
   !> fix the heights; hashing those digests instead of the 2 NP^2 heights again saves
   !> a pass over them).
   function run_fingerprint(problem, options, digests) result(hex)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      !> "FILE sha256 HEX" per input file (input_digests).
      type(string_type), intent(in) :: digests(:)
      character(len=64) :: hex
      character(len=:), allocatable :: text
      integer :: k, at
      text = problem%label//"|"//int_str(problem%np)//"|"//format_real(problem%pixel)//"|"// &
         int_str(problem%maxcont)//"|"//reals(problem%young)//reals(problem%poisson)//history_options(options)//"|"
      do k = 1, size(digests)
         ! The digest without the file's path: a moved input is the same input.
         at = index(digests(k)%s, " sha256 ", back=.true.)
         if (at > 0) then
            text = text//digests(k)%s(at + 8:)//"|"
         else
            text = text//"unreadable|"
         end if
      end do
      hex = sha256_hex(text)
   contains
      function reals(v) result(t)
         real(dp), intent(in) :: v(:)
         character(len=:), allocatable :: t
         integer :: m
         t = ""
         do m = 1, size(v)
            t = t//format_real(v(m))//","
         end do
         t = t//"|"
      end function reals
   end function run_fingerprint

   !> "FILE sha256 HEX" for each input file.
   subroutine input_digests(files, pending, digests)
      type(string_type), intent(in) :: files(:)
      type(file_digest), intent(inout) :: pending(:)
      type(string_type), allocatable, intent(out) :: digests(:)
      character(len=64) :: hex
      integer :: k
      allocate(digests(size(files)))
      do k = 1, size(files)
         hex = file_sha256_finish(pending(k))
         if (len_trim(hex) == 64) then
            digests(k)%s = files(k)%s//" sha256 "//hex
         else
            digests(k)%s = files(k)%s//" (unreadable)"
         end if
      end do
   end subroutine input_digests

   !> Before a long solve: can the results be written there at all?
   subroutine check_writable(prefix, st)
      character(len=*), intent(in) :: prefix
      type(status_type), intent(inout) :: st
      integer :: unit, ios
      open(newunit=unit, file=prefix//".history.csv.part", status="replace", action="write", iostat=ios)
      if (ios /= 0) then
         call set_error(st, STATUS_IO, prefix//".history.csv: cannot write (directory missing or not writable); "// &
            "nothing was run")
         return
      end if
      close(unit, status="delete")
   end subroutine check_writable

   !> A deck whose result files exist fails unless --force.
   subroutine refuse_overwrite(prefix, nloads, st)
      character(len=*), intent(in) :: prefix
      integer, intent(in) :: nloads
      type(status_type), intent(inout) :: st
      type(string_type), allocatable :: names(:)
      integer :: m
      names = result_files(prefix, nloads)
      do m = 1, size(names)
         if (path_exists(names(m)%s)) then
            call set_error(st, STATUS_IO, names(m)%s//": exists; not overwritten (use --force to replace the results)")
            return
         end if
      end do
   end subroutine refuse_overwrite
end module femcod_run

