!> `femcod run DECK [-o PREFIX] [--solver legacy] [--loads F1,F2,...] [--max-contacts N]
!> [--hardness H] [--no-final-check] [--quiet]`: read the deck, run the solver, write
!> PREFIX.history.csv, PREFIX.contacts.csv and (with --loads) PREFIX.loads.csv, and
!> print a summary.
module femcod_run
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, STATUS_USAGE
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str, real_str, split_list, parse_real, parse_integer, &
      format_real, parse_real_list
   use femcod_contact_result, only: contact_result, contact_options, stop_reason_text, solver_state
   use femcod_checkpoint, only: write_checkpoint, read_checkpoint
   use femcod_files, only: remove_file
   use femcod_legacy, only: solve_legacy
   use femcod_incremental, only: solve_incremental, scene_report
   use femcod_cg, only: solve_cg, cg_residuals, cg_method
   use femcod_wisdom, only: load_wisdom, save_wisdom
   use femcod_results, only: write_results, run_info, result_files
   use femcod_maps, only: load_maps, state_maps
   use femcod_generate, only: scene_spec
   use femcod_heights, only: load_scene
   use femcod_files, only: path_exists
   use femcod_about, only: FEMCOD_VERSION
   use femcod_status, only: STATUS_IO, STATUS_NUMERICAL
   implicit none
   private
   public :: run_command, default_prefix, file_part

   !> Elapsed time (s) of the last progress line.
   real(dp), save :: last_report = 0
   !> What the run aims at, for the estimate of the time left: contacts, the largest
   !> requested load (nN, 0 if none) and how the cost of a run grows with the contacts
   !> (n^3 for the incremental solver, n^4 for the legacy one).
   integer, save :: target_contacts = 0
   real(dp), save :: target_load = 0, growth = 3
   !> Where and for what the checkpoint procedure writes (set before each solve).
   character(len=:), allocatable, save :: checkpoint_path
   type(contact_problem), save :: checkpoint_deck
   type(contact_options), save :: checkpoint_options
   logical, save :: checkpoint_warned = .false.

contains

   subroutine run_help()
      write(output_unit, '(a)') &
         "usage: femcod run DECK [DECK ...] [-o PREFIX] [--solver incremental|legacy|cg] [--loads F1,F2,...]", &
         "                  [--max-contacts N] [--hardness H] [--no-final-check] [--quiet] [--force]", &
         "       femcod run --lower FILE [--upper FILE] --pixel D [--young E] [--poisson NU]", &
         "                  [--rigid upper|lower|none] [--maxcont M] [--remove-plane] [options as above]", &
         "", &
         "Contact history of each deck, step by step (thesis chapter 4, Appendix B). With several decks", &
         "(batch) each gets its own outputs named after it; a bad deck is reported and the others still", &
         "run; the exit code is that of the first failure, and a final summary lists the failures.", &
         "  -o PREFIX          output prefix (default: the deck's name without .deck, here)", &
         "  --solver S         incremental (default): event-exact, condensed to the contacts, bordered", &
         "                     Cholesky factor, exact candidate bound, full-field FFT check at the end;", &
         "                     legacy: the Appendix B program (skyline, COLHT, TRFACT, POSTP)", &
         "                     cg: the state at each requested load only, by constrained conjugate", &
         "                     gradients (Polonsky-Keer) with FFT convolutions; --tol T (default 1e-8,", &
         "                     gap violations over the height range), --max-iterations N (default 2000),", &
         "                     --fftw-wisdom FILE: FFTW measures its plans once and keeps them in FILE", &
         "                     and FILE.float32 (seconds of planning the first time, faster transforms)", &
         "  --loads F1,...     total loads in nN at which to report the state (PREFIX.loads.csv);", &
         "                     the run stops once the largest is reached", &
         "  --max-contacts N   stop after N contacts (default: the deck's MAXCONT)", &
         "  --hardness H       GPa, for n_above_hardness (default 11, polysilicon)", &
         "  --no-final-check   skip the final check of every pixel for missed contacts", &
         "  --quiet            no summary on standard output, no progress lines on standard error", &
         "  --event-search E   incremental solver: how the next contact is found. bound: a heap of", &
         "                     lower bounds on the gaps and exact O(n) evaluations of the pixels that", &
         "                     can close first; fft: gaps and rates of every pixel from two FFT", &
         "                     convolutions, then exact evaluations near the minimum; auto (default):", &
         "                     the cheaper by a cost model of both; all three give the same events", &
         "  --checkpoint-interval S  write PREFIX.ckpt.h5 (atomically) every S seconds of wall time", &
         "                     (default 300; 0: after every step; incremental solver); removed at the end", &
         "  --restart          continue from PREFIX.ckpt.h5 if it exists (refused if it belongs to another", &
         "                     deck or other options); the run ends exactly as an uninterrupted one", &
         "  --force            overwrite existing result files (otherwise a deck whose results exist fails", &
         "                     with exit code 5 before it is solved)", &
         "", &
         "heights straight from files, without a deck (one scene; -o defaults to the first file's name):", &
         "  --lower FILE       lower surface heights (nm): an ASCII matrix, or FILE.h5:/dataset (square,", &
         "                     C order: data[i, j] is row i, column j)", &
         "  --upper FILE       upper surface heights, the same formats (missing: flat)", &
         "  --pixel D          pixel size in nm (required)", &
         "  --young E, --poisson NU   the elastic body (default 200 GPa, 0.25)", &
         "  --rigid upper|lower|none  rigid body (default upper), --rigid-factor R (default 1e10), as mkdeck", &
         "  --maxcont M        maximum contacts (default 5 % of the pixels)", &
         "  --remove-plane     subtract each surface's least-squares plane", &
         "", &
         "outputs: PREFIX.history.csv (step,contacts,load_nN,approach_nm,area_nm2,area_fraction,", &
         "         n_above_hardness),", &
         "         PREFIX.contacts.csv (i,j,step,force_nN,pressure_GPa) at the largest requested load", &
         "         or the last step, PREFIX.loads.csv (load_nN,approach_nm,contacts,area_nm2,area_fraction,", &
         "         max_pressure_GPa,n_above_hardness), PREFIX.h5 (everything, with the pressure and gap", &
         "         maps at each requested load; doc/results.md), PREFIX.xdmf (the maps for ParaView),", &
         "         PREFIX.load_approach.svg, PREFIX.area_load.svg, PREFIX.pressure_<k>.svg", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O"
   end subroutine run_help

   subroutine run_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(string_type), allocatable :: decks(:), failed(:)
      character(len=:), allocatable :: deck_path, prefix, solver, key, current_prefix
      type(scene_spec) :: spec
      type(run_info) :: info
      type(solver_state) :: resume
      type(cg_residuals), allocatable :: cg_report(:)
      type(cg_method) :: cg_how
      character(len=:), allocatable :: wisdom
      real(dp) :: cg_tol
      integer :: cg_iterations
      logical :: quiet, ok, force, restart
      integer :: i, k, d, rc
      code = 0
      quiet = .false.
      force = .false.
      restart = .false.
      cg_tol = 1.0e-8_dp
      cg_iterations = 2000
      options%checkpoint_interval = 300
      spec%kind = "matrix"
      spec%label = ""
      spec%matrix_file = ""
      spec%second_file = ""
      info%options = ""
      do k = 1, size(args)
         info%options = info%options//args(k)%s
         if (k < size(args)) info%options = info%options//" "
      end do
      deck_path = ""
      allocate(decks(0), failed(0))
      prefix = ""
      wisdom = ""
      solver = "incremental"
      allocate(options%loads(0))
      i = 1
      do while (i <= size(args))
         key = args(i)%s
         select case (key)
         case ("-h", "--help")
            call run_help()
            return
         case ("--quiet", "-q")
            quiet = .true.
            i = i + 1
            cycle
         case ("--no-final-check")
            options%final_check = .false.
            i = i + 1
            cycle
         case ("--force")
            force = .true.
            i = i + 1
            cycle
         case ("--restart")
            restart = .true.
            i = i + 1
            cycle
         case ("--remove-plane")
            spec%plane = .true.
            i = i + 1
            cycle
         end select
         if (key(1:1) /= "-" .or. len(key) == 1) then
            do d = 1, size(decks)
               if (decks(d)%s == key) then
                  call usage("the deck '"//key//"' is given twice (its results would overwrite each other)")
                  return
               end if
            end do
            decks = [decks, string_type(key)]
            i = i + 1
            cycle
         end if
         if (i == size(args)) then
            call usage("option "//key//" needs a value")
            return
         end if
         associate(v => args(i + 1)%s)
            select case (key)
            case ("-o", "--output")
               prefix = v
            case ("--solver")
               solver = v
               if (solver /= "legacy" .and. solver /= "incremental" .and. solver /= "cg") then
                  call usage("unknown solver '"//v//"' (available: incremental, legacy, cg)")
                  return
               end if
            case ("--loads")
               call parse_real_list(v, options%loads, ok)
               if (ok) ok = all(options%loads >= 0)
               if (.not. ok) then
                  call usage("--loads expects non-negative numbers in nN, found '"//v//"'")
                  return
               end if
            case ("--max-contacts")
               call parse_integer(v, options%max_contacts, ok)
               if (.not. ok .or. options%max_contacts <= 0) then
                  call usage("--max-contacts expects a positive integer, found '"//v//"'")
                  return
               end if
            case ("--hardness")
               call parse_real(v, options%hardness, ok)
               if (.not. ok .or. options%hardness <= 0) then
                  call usage("--hardness expects a positive number in GPa, found '"//v//"'")
                  return
               end if
            case ("--tol")
               call parse_real(v, cg_tol, ok)
               if (.not. ok .or. .not. cg_tol > 0) then
                  call usage("--tol expects a positive number, found '"//v//"'")
                  return
               end if
            case ("--fftw-wisdom")
               wisdom = v
            case ("--max-iterations")
               call parse_integer(v, cg_iterations, ok)
               if (.not. ok .or. cg_iterations <= 0) then
                  call usage("--max-iterations expects a positive integer, found '"//v//"'")
                  return
               end if
            case ("--event-search")
               if (v /= "auto" .and. v /= "bound" .and. v /= "fft") then
                  call usage("--event-search expects auto, bound or fft, found '"//v//"'")
                  return
               end if
               options%event_search = v
            case ("--checkpoint-interval")
               call parse_real(v, options%checkpoint_interval, ok)
               if (.not. ok .or. options%checkpoint_interval < 0) then
                  call usage("--checkpoint-interval expects seconds >= 0, found '"//v//"'")
                  return
               end if
            case ("--lower")
               spec%second_file = v
            case ("--upper")
               spec%matrix_file = v
            case ("--label")
               spec%label = v
            case ("--rigid")
               spec%rigid = v
            case ("--pixel", "--young", "--poisson", "--rigid-factor")
               if (key == "--rigid-factor") then
                  call parse_real(v, spec%rigid_factor, ok)
                  if (ok) ok = spec%rigid_factor >= 1
               end if
               if (key == "--pixel") call parse_real(v, spec%pixel, ok)
               if (key == "--young") call parse_real(v, spec%young, ok)
               if (key == "--poisson") call parse_real(v, spec%poisson, ok)
               if (.not. ok) then
                  call usage(key//" expects a number, found '"//v//"'")
                  return
               end if
            case ("--maxcont")
               call parse_integer(v, spec%maxcont, ok)
               if (.not. ok .or. spec%maxcont <= 0) then
                  call usage("--maxcont expects a positive integer, found '"//v//"'")
                  return
               end if
            case default
               call usage("unknown option "//key)
               return
            end select
         end associate
         i = i + 2
      end do
      if (spec%matrix_file /= "" .or. spec%second_file /= "") then
         ! Heights from files: one scene. The surface given alone carries the shape; with
         ! both, the lower file is the matrix and the upper the second file.
         if (size(decks) > 0) then
            call usage("give either DECK files or --lower/--upper height files, not both")
            return
         end if
         if (.not. spec%pixel > 0) then
            call usage("--lower/--upper need --pixel D, the pixel size in nm")
            return
         end if
         if (spec%matrix_file == "") then
            spec%matrix_file = spec%second_file
            spec%second_file = ""
            spec%shape_on = "lower"
         else if (spec%second_file /= "") then
            ! Both: read the upper as the matrix and the lower as the second surface.
            spec%shape_on = "upper"
         end if
         if (spec%label == "") spec%label = "femcod run "//info%options
         decks = [string_type("")]
         if (prefix == "") prefix = default_prefix(file_part(spec%matrix_file))
      end if
      if (size(decks) == 0) then
         call usage("run needs a DECK")
         return
      end if
      if (restart .and. solver /= "incremental") then
         call usage("--restart: checkpoints are written by the incremental solver only")
         return
      end if
      if (solver == "cg" .and. size(options%loads) == 0) then
         call usage("--solver cg solves at given loads: add --loads F1,F2,...")
         return
      end if
      if (size(decks) > 1 .and. prefix /= "") then
         call usage("-o PREFIX names the outputs of one deck; with several decks each deck's outputs are "// &
            "named after it, in the current directory")
         return
      end if
      ! Batch: every deck runs; a failed deck is reported and the others go on.
      do d = 1, size(decks)
         deck_path = decks(d)%s
         if (prefix /= "") then
            call run_one(prefix, rc)
         else
            call run_one(default_prefix(deck_path), rc)
         end if
         if (rc /= 0) then
            failed = [failed, string_type(deck_path)]
            if (code == 0) code = rc
         end if
      end do
      if (size(decks) > 1) then
         write(output_unit, '(a)') "femcod run: "//int_str(size(decks))//" decks, "//int_str(size(failed))//" failed"
         do d = 1, size(failed)
            write(output_unit, '(a)') "  failed: "//failed(d)%s
         end do
      end if
   contains
      !> One deck: read, solve, write, report. `rc` is its exit code.
      subroutine run_one(out_prefix, rc)
         character(len=*), intent(in) :: out_prefix
         integer, intent(out) :: rc
         type(status_type) :: st
         character(len=160), allocatable :: lines(:)
         type(state_maps), allocatable :: maps(:)
         rc = 0
         current_prefix = out_prefix
         if (deck_path == "") then
            call load_scene(spec, deck, st)
         else
            call read_deck(deck_path, deck, st)
         end if
         ! With --restart, result files are leftovers of the interrupted run while its
         ! checkpoint exists, or while PREFIX.h5 (renamed last) does not; a complete set
         ! without a checkpoint means the run had finished: nothing to do.
         if (st%code == 0 .and. restart .and. .not. force .and. solver == "incremental") then
            if (path_exists(out_prefix//".h5") .and. .not. path_exists(out_prefix//".ckpt.h5")) then
               if (.not. quiet) write(error_unit, '(a)') "femcod: "//out_prefix//".h5: the run of "// &
                  deck_label(deck_path)//" is complete; nothing to restart"
               return
            end if
         end if
         if (st%code == 0) call check_writable(out_prefix, st)
         if (st%code == 0 .and. .not. force) then
            if (.not. (restart .and. (path_exists(out_prefix//".ckpt.h5") .or. &
               .not. path_exists(out_prefix//".h5")))) call refuse_overwrite(out_prefix, st)
         end if
         last_report = 0
         target_contacts = deck%maxcont
         if (options%max_contacts > 0) target_contacts = min(target_contacts, options%max_contacts)
         target_load = 0
         if (size(options%loads) > 0) target_load = maxval(options%loads)
         growth = merge(4.0_dp, 3.0_dp, solver == "legacy")
         if (st%code == 0) then
            select case (solver)
            case ("cg")
               if (len(wisdom) > 0) then
                  cg_how%measure_plans = .true.
                  call load_wisdom(wisdom, ok)
               end if
               call solve_cg(deck, options, cg_tol, cg_iterations, res, cg_report, st, cg_how)
               if (st%code == 0 .and. len(wisdom) > 0) call save_wisdom(wisdom, st)
               if (st%code == 0) then
                  do k = 1, size(cg_report)
                     if (cg_report(k)%residual > cg_tol) then
                        st%code = STATUS_NUMERICAL
                        st%message = "cg: load "//format_real(options%loads(k))//" nN: residual "// &
                           real_str(cg_report(k)%residual, 2)//" after "//int_str(cg_report(k)%iterations)// &
                           " iterations, above --tol "//real_str(cg_tol, 2)//" (raise --max-iterations)"
                        exit
                     end if
                  end do
               end if
            case ("legacy")
               if (quiet) then
                  call solve_legacy(deck, options, res, st)
               else
                  call solve_legacy(deck, options, res, st, report_progress)
               end if
            case default
               checkpoint_path = out_prefix//".ckpt.h5"
               checkpoint_deck = deck
               checkpoint_options = options
               checkpoint_warned = .false.
               if (restart .and. path_exists(checkpoint_path)) then
                  call read_checkpoint(checkpoint_path, deck, options, resume, st)
                  if (st%code == 0) then
                     if (.not. quiet) write(error_unit, '(a)') "femcod: resuming "//deck_label(deck_path)// &
                        " from "//checkpoint_path//" at step "//int_str(resume%step)//" ("//int_str(resume%n)// &
                        " contacts)"
                     if (quiet) then
                        call solve_incremental(deck, options, res, st, checkpoint=write_state, resume=resume)
                     else
                        call solve_incremental(deck, options, res, st, report_progress, write_state, resume)
                     end if
                  end if
               else
                  if (restart .and. .not. quiet) write(error_unit, '(a)') "femcod: no checkpoint "// &
                     checkpoint_path//": starting "//deck_label(deck_path)//" from the beginning"
                  if (quiet) then
                     call solve_incremental(deck, options, res, st, checkpoint=write_state)
                  else
                     call solve_incremental(deck, options, res, st, report_progress, write_state)
                  end if
               end if
            end select
         end if
         if (st%code == 0) then
            info%version = FEMCOD_VERSION
            info%solver = solver
            if (solver == "incremental") then
               lines = scene_report(deck)
               allocate(info%scene(size(lines)))
               do k = 1, size(lines)
                  info%scene(k)%s = trim(lines(k))
               end do
            else
               allocate(info%scene(1))
               if (solver == "cg") then
                  info%scene(1)%s = "handles and springs condensed: one composite compliance c1 + c2 with the springs' "// &
                     "3/k on the diagonal, one composite gap"
               else
                  info%scene(1)%s = "nothing: the legacy solver models every node and spring of Appendix B"
               end if
            end if
            call load_maps(deck, res%states, maps)
            call write_results(current_prefix, deck, res, maps, info, st)
            deallocate(info%scene)
         end if
         if (st%code /= 0) then
            write(error_unit, '(a)') "femcod: "//st%message
            rc = st%code
            return
         end if
         ! The results are safe: the checkpoint has served its purpose.
         if (solver == "incremental") call remove_file(out_prefix//".ckpt.h5")
         do k = 1, size(res%states)
            if (.not. res%states(k)%reached) write(error_unit, '(a)') "femcod: warning: load "// &
               format_real(res%states(k)%load)//" nN not reached ("//stop_reason_text(res%stop_reason)//")"
         end do
         if (.not. quiet) call print_summary()
      end subroutine run_one

      !> Before a long solve: can the results be written there at all?
      subroutine check_writable(out_prefix, st)
         character(len=*), intent(in) :: out_prefix
         type(status_type), intent(inout) :: st
         integer :: unit, ios
         open(newunit=unit, file=out_prefix//".history.csv.part", status="replace", action="write", iostat=ios)
         if (ios /= 0) then
            st%code = STATUS_IO
            st%message = out_prefix//".history.csv: cannot write (directory missing or not writable); nothing was run"
            return
         end if
         close(unit, status="delete")
      end subroutine check_writable

      !> A deck whose result files exist fails unless --force.
      subroutine refuse_overwrite(out_prefix, st)
         character(len=*), intent(in) :: out_prefix
         type(status_type), intent(inout) :: st
         type(string_type), allocatable :: names(:)
         integer :: m
         names = result_files(out_prefix, size(options%loads))
         do m = 1, size(names)
            if (path_exists(names(m)%s)) then
               st%code = STATUS_IO
               st%message = names(m)%s//": exists; not overwritten (use --force to replace the results)"
               return
            end if
         end do
      end subroutine refuse_overwrite

      subroutine usage(message)
         character(len=*), intent(in) :: message
         write(error_unit, '(a)') "femcod run: "//message//" (femcod run --help)"
         code = STATUS_USAGE
      end subroutine usage

      subroutine print_summary()
         integer :: last
         character(len=160), allocatable :: lines(:)
         last = res%nsteps
         write(output_unit, '(a)') "femcod run "//deck_path//" (solver "//solver//")"
         write(output_unit, '(a)') "  scene     : "//deck%label
         write(output_unit, '(a)') "              NP = "//int_str(deck%np)//", d = "//format_real(deck%pixel)// &
            " nm, E = "//real_str(deck%young(1), 4)//" / "//real_str(deck%young(2), 4)//" / "// &
            real_str(deck%young(3), 4)//" GPa (lower / upper / contact)"
         write(output_unit, '(a)') "  steps     : "//int_str(last)//", stopped: "//stop_reason_text(res%stop_reason)
         if (last > 0) then
            write(output_unit, '(a)') "  last step : "//int_str(res%step_contacts(last))//" contacts up to load "// &
               real_str(res%step_load(last), 6)//" nN (where the next contact closes), approach "// &
               real_str(res%step_approach(last), 6)//" nm"
         end if
         do k = 1, size(res%states)
            if (.not. res%states(k)%reached) cycle
            write(output_unit, '(a)') "  at load   : "//real_str(res%states(k)%load, 6)//" nN: approach "// &
               real_str(res%states(k)%approach, 6)//" nm, "//int_str(res%states(k)%contacts)//" contacts ("// &
               real_str(res%states(k)%contacts*deck%pixel**2, 4)//" nm^2), max pressure "// &
               real_str(res%states(k)%max_pressure, 4)//" GPa"
         end do
         write(output_unit, '(a)') "  wall time : "//real_str(res%wall_seconds, 3)//" s in total, "// &
            real_str(res%wall_seconds/max(last, 1), 3)//" s per step"
         if (solver == "cg") then
            do k = 1, size(res%states)
               write(output_unit, '(a)') "  cg        : load "//real_str(res%states(k)%load, 6)//" nN: "// &
                  int_str(res%states(k)%iterations)//" iterations, residual "//real_str(res%states(k)%residual, 2)// &
                  ", penetration "//real_str(res%states(k)%penetration, 2)//" nm, |gap| on contact "// &
                  real_str(res%states(k)%contact_gap, 2)//" nm, load error "//real_str(res%states(k)%load_error, 2)
            end do
         else if (solver == "incremental") then
            lines = scene_report(deck)
            do k = 1, size(lines)
               write(output_unit, '(a)') "  model     : "//trim(lines(k))
            end do
            write(output_unit, '(a)') "  checked   : every pixel by FFT convolution at the end: "// &
               int_str(res%missed_final_check)//" penetrating (deepest "//real_str(res%max_penetration, 2)// &
               " nm); "//int_str(res%releases)//" releases; "//real_str(real(res%evaluations, dp), 3)// &
               " exact pixel evaluations; exact re-solve differs by "// &
               real_str(res%final_check_difference, 2)
            write(output_unit, '(a)') "  search    : "//int_str(res%fft_steps)//" of "//int_str(res%nsteps)// &
               " steps by full-field FFT, the others by the gap bound (--event-search "// &
               trim(options%event_search)//")"
            write(output_unit, '(a)') "  cache     : "//int_str(res%cache_hits)//" contacts bordered from the candidate "// &
               "cache, "//int_str(res%cache_misses)//" by their own triangular solves; "//int_str(res%cache_refills)// &
               " refills ("//int_str(res%cache_columns)//" columns by BLAS-3 solves)"
         else
            write(output_unit, '(a)') "  checked   : "//int_str(res%missed_during_run)// &
               " contacts found late by the candidate search, "//int_str(res%missed_final_check)// &
               " found by the final check of all pixels; exact re-solve differs by "// &
               real_str(res%final_check_difference, 2)
            write(output_unit, '(a)') "  TRFACT    : condition estimate "//real_str(res%condition, 2)// &
               " (LAPACK dlacn2): relative errors up to about "//real_str(epsilon(1.0_dp)*res%condition, 1)
            if (epsilon(1.0_dp)*res%condition > 1.0e-8_dp) write(output_unit, '(a)') &
               "  warning   : the stiff springs and rigid body cost the legacy solver digits; the incremental "// &
               "solver is immune (doc/stability.md)"
         end if
         write(output_unit, '(a)') "  written   : "//current_prefix//".h5, .xdmf, .history.csv, .contacts.csv, "// &
            ".load_approach.svg, .area_load.svg"//trim(merge(", .loads.csv, .pressure_<k>.svg", &
            repeat(" ", 31), size(res%states) > 0))
      end subroutine print_summary
   end subroutine run_command

   !> A progress line on standard error at most every 5 s (a module procedure, not an
   !> internal one, so that passing it needs no trampoline on the stack).
   subroutine report_progress(step, contacts, load, elapsed)
      integer, intent(in) :: step, contacts
      real(dp), intent(in) :: load, elapsed
      real(dp) :: fraction, left
      character(len=:), allocatable :: estimate
      if (elapsed - last_report < 5) return
      last_report = elapsed
      ! Time left from the cost model: a run to n contacts costs ~ n**growth; with a
      ! load target, the fraction of the load reached bounds the fraction of contacts.
      fraction = real(contacts, dp)/max(target_contacts, 1)
      if (target_load > 0) fraction = max(fraction, min(load/target_load, 1.0_dp))
      estimate = ""
      if (fraction > 0 .and. fraction < 1) then
         left = elapsed*(fraction**(-growth) - 1)
         estimate = ", about "//real_str(left, 2)//" s left (cost ~ contacts^"//int_str(nint(growth))//")"
      end if
      write(error_unit, '(a)') "femcod: event "//int_str(step)//", "//int_str(contacts)//" contacts, load "// &
         real_str(load, 5)//" nN, "//real_str(elapsed, 3)//" s elapsed"//estimate
      flush(error_unit)
   end subroutine report_progress

   !> The checkpoint procedure handed to the incremental solver: store its state; a
   !> failure to write is reported once and the run goes on.
   subroutine write_state(state)
      type(solver_state), intent(in) :: state
      type(status_type) :: st
      call write_checkpoint(checkpoint_path, checkpoint_deck, checkpoint_options, state, st)
      if (st%code /= 0 .and. .not. checkpoint_warned) then
         write(error_unit, '(a)') "femcod: warning: checkpoint not written: "//st%message
         flush(error_unit)
         checkpoint_warned = .true.
      end if
   end subroutine write_state

   !> How a deck is named in messages.
   function deck_label(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      name = path
      if (path == "") name = "the height files"
   end function deck_label

   !> The file part of `FILE.h5:/dataset`.
   function file_part(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      integer :: colon
      colon = index(path, ":/", back=.true.)
      name = path
      if (colon > 0) name = path(1:colon - 1)
   end function file_part

   !> The deck's file name without directory and without `.deck`.
   function default_prefix(path) result(prefix)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: prefix
      integer :: slash
      slash = index(path, "/", back=.true.)
      prefix = path(slash + 1:)
      slash = index(prefix, ".", back=.true.)
      if (slash > 1) then
         select case (prefix(slash:))
         case (".deck", ".txt", ".dat", ".asc", ".h5", ".hdf5", ".csv")
            prefix = prefix(1:slash - 1)
         end select
      end if
   end function default_prefix
end module femcod_run
