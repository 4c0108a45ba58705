!> femcod as a C library (libfemcod.so, header capi/femcod.h): the top layer, over the run
!> options (cli), the deck readers and writers (io) and the one solver interface
!> (solvers/femcod_solver). A caller makes a session, gives it a problem (height arrays
!> and materials, or a deck file), sets `femcod run`'s options by name, solves, and
!> copies the results into arrays it owns. Nothing here prints or stops: every function
!> returns a status code with the exit codes' meanings (0 ok, 2 usage, 3 bad input,
!> 4 numerical failure or memory, 5 I/O, 6 stopped by the progress callback) and keeps
!> the message of the last failure in the session (femcod_message).
!>
!> Arrays cross in C order, as in the HDF5 files: `a[i*np + j]` is row i, column j.
!> Heights in nm, pixel in nm, moduli in GPa, loads in nN.
!>
!> A session is an opaque C pointer to a Fortran object: C holds no Fortran type, and a
!> pointer is the one way to hand an object's address across (femcod_create allocates
!> it, femcod_destroy frees it).
module femcod_capi
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double, c_char, c_ptr, c_funptr, c_null_ptr, &
      c_null_char, c_null_funptr, c_loc, c_f_pointer, c_f_procpointer, c_associated, c_size_t
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_BAD_INPUT
   use femcod_strings, only: string_type, int_str
   use femcod_about, only: VERSION_TEXT => FEMCOD_VERSION
   use femcod_problem, only: contact_problem, validate_problem
   use femcod_generate, only: scene_spec, build_problem, rough_maxcont
   use femcod_deck, only: read_deck, write_deck
   use femcod_heights, only: load_scene
   use femcod_output_guard, only: guard_outputs, OUTPUT_DECK, OUTPUT_RESULT
   use femcod_results, only: write_results, result_files, run_info
   use femcod_report_command, only: make_report
   use femcod_solver, only: model_notes, run_warnings
   use femcod_process, only: host_name, openmp_threads, wait_policy_text, local_time_iso
   !$ use omp_lib, only: omp_set_num_threads
   use femcod_library_session, only: library_session, solve_session, state_value, state_value_names, state_value_kinds, &
      history_column, HISTORY_COLUMNS, map_of, map_names, library_options
   implicit none
   private
   public :: femcod_create, femcod_destroy, femcod_version, femcod_message, femcod_set_heights, femcod_set_problem, &
      femcod_read_deck, femcod_write_deck, femcod_problem_size, femcod_get_problem, femcod_get_label, &
      femcod_set_option, femcod_clear_options, femcod_solve, femcod_state_count, femcod_state_value, &
      femcod_value_names, femcod_state_map, femcod_history_length, femcod_history, femcod_set_threads, &
      femcod_read_heights, femcod_warnings, femcod_option_names, femcod_write_results, femcod_report

   !> Longest C string read from a caller (a path, an option's value).
   integer, parameter :: MAX_C_STRING = 1048576

contains

   !> A new session, or NULL when there is no memory for it.
   function femcod_create() result(handle) bind(C, name="femcod_create")
      type(c_ptr) :: handle
      type(library_session), pointer :: session
      integer :: stat
      allocate(session, stat=stat)
      handle = c_null_ptr
      if (stat /= 0) return
      session%message = ""
      allocate(session%args(0))
      handle = c_loc(session)
   end function femcod_create

   !> Free a session and everything it holds (NULL: nothing).
   subroutine femcod_destroy(handle) bind(C, name="femcod_destroy")
      type(c_ptr), value :: handle
      type(library_session), pointer :: session
      if (.not. session_of(handle, session)) return
      deallocate(session)
   end subroutine femcod_destroy

   !> femcod's version into `text` (`length` bytes with the terminating NUL).
   integer(c_int) function femcod_version(text, length) bind(C, name="femcod_version")
      integer(c_size_t), value :: length
      type(c_ptr), value :: text
      character(kind=c_char), pointer :: text_out(:)
      if (.not. all_given([text])) then
         femcod_version = null_argument(c_null_ptr, "femcod_version", "text")
         return
      end if
      call c_f_pointer(text, text_out, [max(1_c_size_t, length)])
      femcod_version = copy_out(VERSION_TEXT, text_out, length)
   end function femcod_version

   !> The options femcod_set_option takes, `femcod run`'s names separated by spaces (from
   !> the solver's option table: those that shape the answer).
   integer(c_int) function femcod_option_names(text, length) bind(C, name="femcod_option_names")
      integer(c_size_t), value :: length
      type(c_ptr), value :: text
      character(kind=c_char), pointer :: text_out(:)
      if (.not. all_given([text])) then
         femcod_option_names = null_argument(c_null_ptr, "femcod_option_names", "text")
         return
      end if
      call c_f_pointer(text, text_out, [max(1_c_size_t, length)])
      femcod_option_names = copy_out(library_options(), text_out, length)
   end function femcod_option_names

   !> The message of the session's last failure ("" after a success).
   integer(c_int) function femcod_message(handle, text, length) bind(C, name="femcod_message")
      type(c_ptr), value :: handle
      integer(c_size_t), value :: length
      type(library_session), pointer :: session
      type(c_ptr), value :: text
      character(kind=c_char), pointer :: text_out(:)
      if (.not. all_given([text])) then
         femcod_message = null_argument(handle, "femcod_message", "text")
         return
      end if
      call c_f_pointer(text, text_out, [max(1_c_size_t, length)])
      femcod_message = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      femcod_message = copy_out(session%message, text_out, length)
   end function femcod_message

   !> The problem of `femcod run --lower L [--upper U] --pixel D --young E --poisson NU`:
   !> the surface given alone is the elastic body's (lower), the other body rigid and
   !> flat; with `upper` (not NULL) both are rough. Each surface is taken from its
   !> lowest point. MAXCONT <= 0: 5 % of NP^2.
   integer(c_int) function femcod_set_heights(handle, np, pixel, lower, upper, young, poisson, maxcont) &
      bind(C, name="femcod_set_heights")
      type(c_ptr), value :: handle
      integer(c_int), value :: np, maxcont
      real(c_double), value :: pixel, young, poisson
      real(c_double), intent(in) :: lower(*)
      type(c_ptr), value :: upper
      type(library_session), pointer :: session
      type(scene_spec) :: spec
      type(status_type) :: st
      real(c_double), pointer :: top(:)
      femcod_set_heights = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      call forget_problem(session)
      if (np <= 0) call set_error(st, STATUS_BAD_INPUT, "np must be positive, found "//int_str(int(np)))
      if (st%code == 0) then
         spec%kind = "matrix"
         spec%label = "femcod library"
         spec%pixel = pixel
         spec%young = young
         spec%poisson = poisson
         spec%maxcont = max(0, int(maxcont))
         spec%matrix_file = "the lower heights"
         spec%second_file = ""
         spec%shape_on = "lower"
         if (c_associated(upper)) then
            call c_f_pointer(upper, top, [int(np)*int(np)])
            spec%matrix_file = "the upper heights"
            spec%second_file = "the lower heights"
            spec%shape_on = "upper"
            call build_problem(spec, session%problem, st, c_order(top, int(np)), c_order(lower, int(np)))
         else
            call build_problem(spec, session%problem, st, c_order(lower, int(np)))
         end if
      end if
      femcod_set_heights = finish_problem(session, st)
   end function femcod_set_heights

   !> A problem as a deck gives it: both height maps, the three moduli and Poisson's
   !> ratios (lower, upper, contact elements), MAXCONT (<= 0: 5 % of NP^2, as for a
   !> rough scene) and a one-line label.
   integer(c_int) function femcod_set_problem(handle, np, pixel, lower, upper, young, poisson, maxcont, label) &
      bind(C, name="femcod_set_problem")
      type(c_ptr), value :: handle
      integer(c_int), value :: np, maxcont
      real(c_double), value :: pixel
      real(c_double), intent(in) :: lower(*), upper(*), young(3), poisson(3)
      character(kind=c_char), intent(in) :: label(*)
      type(library_session), pointer :: session
      type(status_type) :: st
      femcod_set_problem = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      call forget_problem(session)
      if (np <= 0) then
         call set_error(st, STATUS_BAD_INPUT, "np must be positive, found "//int_str(int(np)))
      else
         associate(p => session%problem)
            p%label = from_c(label)
            p%np = np
            p%pixel = pixel
            p%maxcont = maxcont
            if (maxcont <= 0) p%maxcont = rough_maxcont(int(np))
            p%young = young
            p%poisson = poisson
            p%lower = c_order(lower, int(np))
            p%upper = c_order(upper, int(np))
         end associate
         call validate_problem(session%problem, st)
      end if
      femcod_set_problem = finish_problem(session, st)
   end function femcod_set_problem

   !> The problem of a deck file (text or HDF5), read with femcod run's checks.
   integer(c_int) function femcod_read_deck(handle, path) bind(C, name="femcod_read_deck")
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: path(*)
      type(library_session), pointer :: session
      type(status_type) :: st
      femcod_read_deck = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      call forget_problem(session)
      call read_deck(from_c(path), session%problem, st)
      femcod_read_deck = finish_problem(session, st)
   end function femcod_read_deck

   !> The problem of `femcod run --lower PATH [--pixel D] [--remove-plane] --young E
   !> --poisson NU`: a height file (an ASCII matrix or Gwyddion export, FILE.h5:/DATASET,
   !> a NanoScope file FILE[:CHANNEL]) on an elastic body against a rigid flat. pixel <= 0:
   !> the file's own. What run warns of (a tilt, a guessed unit) is in femcod_warnings.
   integer(c_int) function femcod_read_heights(handle, path, pixel, remove_plane, young, poisson) &
      bind(C, name="femcod_read_heights")
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: path(*)
      real(c_double), value :: pixel, young, poisson
      integer(c_int), value :: remove_plane
      type(library_session), pointer :: session
      type(scene_spec) :: spec
      type(status_type) :: st
      type(string_type), allocatable :: notes(:), warnings(:)
      integer :: k
      femcod_read_heights = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      call forget_problem(session)
      spec%kind = "matrix"
      spec%matrix_file = from_c(path)
      spec%second_file = ""
      spec%shape_on = "lower"
      spec%label = "femcod library: "//spec%matrix_file
      spec%pixel = max(0.0_dp, pixel)
      spec%plane = remove_plane /= 0
      spec%young = young
      spec%poisson = poisson
      call load_scene(spec, session%problem, st, notes, warnings)
      session%warnings = ""
      if (allocated(warnings)) then
         do k = 1, size(warnings)
            session%warnings = session%warnings//warnings(k)%s//new_line("a")
         end do
      end if
      femcod_read_heights = finish_problem(session, st)
   end function femcod_read_heights

   !> What the last read of heights or the last solve warned of, one warning per line ("":
   !> nothing): a tilt or a guessed unit of a height file, a requested state not reached,
   !> a tangential step at a state without contact.
   integer(c_int) function femcod_warnings(handle, text, length) bind(C, name="femcod_warnings")
      type(c_ptr), value :: handle
      integer(c_size_t), value :: length
      type(library_session), pointer :: session
      type(c_ptr), value :: text
      character(kind=c_char), pointer :: text_out(:)
      if (.not. all_given([text])) then
         femcod_warnings = null_argument(handle, "femcod_warnings", "text")
         return
      end if
      call c_f_pointer(text, text_out, [max(1_c_size_t, length)])
      femcod_warnings = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (.not. allocated(session%warnings)) session%warnings = ""
      femcod_warnings = copy_out(session%warnings, text_out, length)
   end function femcod_warnings

   !> Write the session's problem as a deck (a name ending in .h5: the HDF5 deck),
   !> atomically. An existing file is replaced only with `force` /= 0, and only if femcod
   !> wrote it (femcod mkdeck's rule).
   integer(c_int) function femcod_write_deck(handle, path, force) bind(C, name="femcod_write_deck")
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: force
      type(library_session), pointer :: session
      type(status_type) :: st
      character(len=:), allocatable :: name
      femcod_write_deck = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      name = from_c(path)
      if (.not. session%has_problem) call set_error(st, STATUS_USAGE, "no problem to write: set one first")
      call guard_outputs([string_type(name)], [string_type :: ], force /= 0, OUTPUT_DECK, st)
      if (st%code == 0) call write_deck(name, session%problem, st)
      femcod_write_deck = finish(session, st)
   end function femcod_write_deck

   !> Write the last solve's result set under `prefix`, the files `femcod run -o PREFIX`
   !> writes (PREFIX.h5, .xdmf, .summary.json, the CSV tables and figures), atomically as
   !> a set. Existing results are replaced only with `force` /= 0, and only if femcod
   !> wrote them.
   integer(c_int) function femcod_write_results(handle, prefix, force) bind(C, name="femcod_write_results")
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: prefix(*)
      integer(c_int), value :: force
      type(library_session), pointer :: session
      type(status_type) :: st
      type(run_info) :: info
      character(len=:), allocatable :: name
      femcod_write_results = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      name = from_c(prefix)
      if (.not. session%solved) call set_error(st, STATUS_USAGE, "no result to write: solve first")
      if (name == "") call set_error(st, STATUS_USAGE, "expected a prefix for the result files, found none")
      if (st%code == 0) call guard_outputs(result_files(name, size(session%res%states)), [string_type :: ], force /= 0, &
         OUTPUT_RESULT, st)
      if (st%code == 0) then
         info = session%info
         info%version = VERSION_TEXT
         info%command_line = "libfemcod (femcod_solve)"
         info%host = host_name()
         info%threads = openmp_threads()
         info%wait_policy = wait_policy_text()
         info%finished = local_time_iso()
         info%scene = model_notes(session%problem, session%options)
         info%warnings = run_warnings(session%options, session%res)
         call write_results(name, session%problem, session%res, session%maps, info, st)
      end if
      femcod_write_results = finish(session, st)
   end function femcod_write_results

   !> `femcod report TARGET -o OUTPUT`: the HTML page of a result set's prefix or of a
   !> results directory (OUTPUT "": the default name). The page's path is copied
   !> into `page` (at most `capacity` bytes with the NUL). The session only keeps the
   !> message of a failure.
   integer(c_int) function femcod_report(handle, target, output, force, page, capacity) bind(C, name="femcod_report")
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: target(*), output(*)
      integer(c_int), value :: force
      character(kind=c_char), intent(out) :: page(*)
      integer(c_size_t), value :: capacity
      type(library_session), pointer :: session
      type(status_type) :: st
      type(string_type), allocatable :: written(:)
      character(len=:), allocatable :: path
      integer :: bytes
      femcod_report = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      path = from_c(output)
      call make_report(from_c(target), path, force /= 0, written, bytes, st)
      if (st%code == 0) then
         if (copy_out(path, page, capacity) /= 0) call set_error(st, STATUS_USAGE, "the page's path needs "// &
            int_str(len(path) + 1)//" bytes, the buffer has "//int_str(int(capacity)))
      end if
      femcod_report = finish(session, st)
   end function femcod_report

   !> NP of the session's problem (0: none).
   integer(c_int) function femcod_problem_size(handle, np) bind(C, name="femcod_problem_size")
      type(c_ptr), value :: handle
      type(library_session), pointer :: session
      type(c_ptr), value :: np
      integer(c_int), pointer :: np_out
      if (.not. all_given([np])) then
         femcod_problem_size = null_argument(handle, "femcod_problem_size", "np")
         return
      end if
      call c_f_pointer(np, np_out)
      np_out = 0
      femcod_problem_size = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (session%has_problem) np_out = session%problem%np
      femcod_problem_size = 0
   end function femcod_problem_size

   !> The session's problem into caller arrays: pixel, MAXCONT, the three moduli and
   !> ratios, and the NP x NP heights (C order).
   integer(c_int) function femcod_get_problem(handle, pixel, maxcont, young, poisson, lower, upper) &
      bind(C, name="femcod_get_problem")
      type(c_ptr), value :: handle
      type(library_session), pointer :: session
      type(status_type) :: st
      integer :: n
      type(c_ptr), value :: pixel
      type(c_ptr), value :: young
      type(c_ptr), value :: poisson
      type(c_ptr), value :: lower
      type(c_ptr), value :: upper
      type(c_ptr), value :: maxcont
      real(c_double), pointer :: pixel_out
      real(c_double), pointer :: young_out(:)
      real(c_double), pointer :: poisson_out(:)
      real(c_double), pointer :: lower_out(:)
      real(c_double), pointer :: upper_out(:)
      integer(c_int), pointer :: maxcont_out
      if (.not. all_given([pixel, young, poisson, lower, upper, maxcont])) then
         femcod_get_problem = null_argument(handle, "femcod_get_problem", "pixel, young, poisson, lower, upper, maxcont")
         return
      end if
      call c_f_pointer(pixel, pixel_out)
      call c_f_pointer(young, young_out, [3])
      call c_f_pointer(poisson, poisson_out, [3])
      call c_f_pointer(maxcont, maxcont_out)
      femcod_get_problem = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (.not. session%has_problem) then
         call set_error(st, STATUS_USAGE, "no problem: set one or read a deck first")
      else
         associate(p => session%problem)
            n = p%np
            pixel_out = p%pixel
            maxcont_out = p%maxcont
            young_out = p%young
            poisson_out = p%poisson
            call c_f_pointer(lower, lower_out, [n*n])
            call c_f_pointer(upper, upper_out, [n*n])
            call to_c_order(p%lower, lower_out)
            call to_c_order(p%upper, upper_out)
         end associate
      end if
      femcod_get_problem = finish(session, st)
   end function femcod_get_problem

   !> The problem's label into `text`.
   integer(c_int) function femcod_get_label(handle, text, length) bind(C, name="femcod_get_label")
      type(c_ptr), value :: handle
      integer(c_size_t), value :: length
      type(library_session), pointer :: session
      type(c_ptr), value :: text
      character(kind=c_char), pointer :: text_out(:)
      if (.not. all_given([text])) then
         femcod_get_label = null_argument(handle, "femcod_get_label", "text")
         return
      end if
      call c_f_pointer(text, text_out, [max(1_c_size_t, length)])
      femcod_get_label = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (.not. session%has_problem) return
      femcod_get_label = copy_out(session%problem%label, text_out, length)
   end function femcod_get_label

   !> Add one of `femcod run`'s options by its name ("--solver") and value ("cg"; "" for
   !> a flag such as "--plastic"). The rules between options are checked at the solve,
   !> by run's own parser, before any work.
   integer(c_int) function femcod_set_option(handle, name, value) bind(C, name="femcod_set_option")
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: name(*), value(*)
      type(library_session), pointer :: session
      type(status_type) :: st
      character(len=:), allocatable :: key, text
      femcod_set_option = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      key = from_c(name)
      text = from_c(value)
      session%args = [session%args, string_type(key)]
      if (len(text) > 0) session%args = [session%args, string_type(text)]
      femcod_set_option = finish(session, st)
   end function femcod_set_option

   !> Forget every option set.
   integer(c_int) function femcod_clear_options(handle) bind(C, name="femcod_clear_options")
      type(c_ptr), value :: handle
      type(library_session), pointer :: session
      femcod_clear_options = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      session%args = [string_type :: ]
      femcod_clear_options = 0
   end function femcod_clear_options

   !> Solve the session's problem with its options. `progress` (may be NULL) is called
   !> after every step or state and, while the solver iterates, at least every 0.1 s:
   !> int progress(int step, int contacts, double load_nN, double seconds, void *user);
   !> a non-zero return stops the solve, which then returns 6 and keeps no result.
   integer(c_int) function femcod_solve(handle, progress, user) bind(C, name="femcod_solve")
      type(c_ptr), value :: handle
      type(c_funptr), value :: progress
      type(c_ptr), value :: user
      type(library_session), pointer :: session
      type(status_type) :: st
      femcod_solve = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      call solve_session(session, progress, user, st)
      femcod_solve = finish(session, st)
   end function femcod_solve

   !> The threads of the solvers and FFTW for the whole process (OpenMP's
   !> omp_set_num_threads; the default is OMP_NUM_THREADS or every core).
   integer(c_int) function femcod_set_threads(threads) bind(C, name="femcod_set_threads")
      integer(c_int), value :: threads
      femcod_set_threads = STATUS_USAGE
      if (threads < 1) return
      !$ call omp_set_num_threads(int(threads))
      femcod_set_threads = 0
   end function femcod_set_threads

   !> The number of states of the last solve (one per load or approach asked; for the
   !> event solvers without --loads, the last step).
   integer(c_int) function femcod_state_count(handle, count) bind(C, name="femcod_state_count")
      type(c_ptr), value :: handle
      type(library_session), pointer :: session
      type(status_type) :: st
      type(c_ptr), value :: count
      integer(c_int), pointer :: count_out
      if (.not. all_given([count])) then
         femcod_state_count = null_argument(handle, "femcod_state_count", "count")
         return
      end if
      call c_f_pointer(count, count_out)
      count_out = 0
      femcod_state_count = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (.not. session%solved) then
         call set_error(st, STATUS_USAGE, "no result: solve first")
      else if (allocated(session%res%states)) then
         count_out = size(session%res%states)
      end if
      femcod_state_count = finish(session, st)
   end function femcod_state_count

   !> The names (comma-separated) of what the last solve has: `kind` 0 the state values
   !> (femcod_state_value), 1 the maps (femcod_state_map), 2 the history columns; 3 the
   !> state values' kinds in the order of 0: number, count (an integer) or flag (1 or 0).
   integer(c_int) function femcod_value_names(handle, kind, text, length) bind(C, name="femcod_value_names")
      type(c_ptr), value :: handle
      integer(c_int), value :: kind
      integer(c_size_t), value :: length
      type(library_session), pointer :: session
      type(status_type) :: st
      type(c_ptr), value :: text
      character(kind=c_char), pointer :: text_out(:)
      if (.not. all_given([text])) then
         femcod_value_names = null_argument(handle, "femcod_value_names", "text")
         return
      end if
      call c_f_pointer(text, text_out, [max(1_c_size_t, length)])
      femcod_value_names = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (.not. session%solved) then
         call set_error(st, STATUS_USAGE, "no result: solve first")
         femcod_value_names = finish(session, st)
         return
      end if
      select case (kind)
      case (0)
         femcod_value_names = copy_out(state_value_names(session), text_out, length)
      case (1)
         femcod_value_names = copy_out(map_names(session), text_out, length)
      case (2)
         femcod_value_names = copy_out(HISTORY_COLUMNS, text_out, length)
      case (3)
         femcod_value_names = copy_out(state_value_kinds(session), text_out, length)
      case default
         call set_error(st, STATUS_USAGE, "kind must be 0 (state values), 1 (maps), 2 (history) or 3 (the kinds "// &
            "of the state values)")
         femcod_value_names = finish(session, st)
      end select
   end function femcod_value_names

   !> One number of state k (1-based) by name (femcod_value_names 0; counts as reals).
   integer(c_int) function femcod_state_value(handle, k, name, value) bind(C, name="femcod_state_value")
      type(c_ptr), value :: handle
      integer(c_int), value :: k
      character(kind=c_char), intent(in) :: name(*)
      type(library_session), pointer :: session
      type(status_type) :: st
      type(c_ptr), value :: value
      real(c_double), pointer :: value_out
      if (.not. all_given([value])) then
         femcod_state_value = null_argument(handle, "femcod_state_value", "value")
         return
      end if
      call c_f_pointer(value, value_out)
      value_out = 0
      femcod_state_value = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      call check_state(session, int(k), st)
      if (st%code == 0) call state_value(session, int(k), from_c(name), value_out, st)
      femcod_state_value = finish(session, st)
   end function femcod_state_value

   !> One NP x NP map of state k by name ("pressure" GPa, "gap" nm, "plastic_displacement"
   !> nm; with a tangential step "shear_x", "shear_y" GPa, "stick", "slip") into `out` (C
   !> order, `size` doubles, which must be NP^2).
   integer(c_int) function femcod_state_map(handle, k, name, out, size) bind(C, name="femcod_state_map")
      type(c_ptr), value :: handle
      integer(c_int), value :: k
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int64_t), value :: size
      type(library_session), pointer :: session
      type(status_type) :: st
      real(dp), allocatable :: map(:, :)
      integer :: n
      type(c_ptr), value :: out
      real(c_double), pointer :: out_out(:)
      if (.not. all_given([out])) then
         femcod_state_map = null_argument(handle, "femcod_state_map", "out")
         return
      end if
      call c_f_pointer(out, out_out, [max(1_c_int64_t, size)])
      femcod_state_map = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      call check_state(session, int(k), st)
      if (st%code == 0) then
         n = session%problem%np
         if (size /= int(n, c_int64_t)**2) then
            call set_error(st, STATUS_USAGE, "the map needs NP^2 = "//int_str(n*n)//" doubles")
         else
            call map_of(session, int(k), from_c(name), map, st)
            if (st%code == 0) call to_c_order(map, out_out(1:n*n))
         end if
      end if
      femcod_state_map = finish(session, st)
   end function femcod_state_map

   !> The number of steps in the history of the last solve.
   integer(c_int) function femcod_history_length(handle, steps) bind(C, name="femcod_history_length")
      type(c_ptr), value :: handle
      type(library_session), pointer :: session
      type(status_type) :: st
      type(c_ptr), value :: steps
      integer(c_int), pointer :: steps_out
      if (.not. all_given([steps])) then
         femcod_history_length = null_argument(handle, "femcod_history_length", "steps")
         return
      end if
      call c_f_pointer(steps, steps_out)
      steps_out = 0
      femcod_history_length = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (.not. session%solved) call set_error(st, STATUS_USAGE, "no result: solve first")
      if (st%code == 0) steps_out = session%res%nsteps
      femcod_history_length = finish(session, st)
   end function femcod_history_length

   !> One column of the history (femcod_value_names 2) into `out` (`size` doubles, the
   !> history's length).
   integer(c_int) function femcod_history(handle, name, out, size) bind(C, name="femcod_history")
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int64_t), value :: size
      type(library_session), pointer :: session
      type(status_type) :: st
      real(dp), allocatable :: column(:)
      type(c_ptr), value :: out
      real(c_double), pointer :: out_out(:)
      if (.not. all_given([out])) then
         femcod_history = null_argument(handle, "femcod_history", "out")
         return
      end if
      call c_f_pointer(out, out_out, [max(1_c_int64_t, size)])
      femcod_history = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      if (.not. session%solved) call set_error(st, STATUS_USAGE, "no result: solve first")
      if (st%code == 0) call history_column(session, from_c(name), column, st)
      if (st%code == 0) then
         if (size /= int(session%res%nsteps, c_int64_t)) then
            call set_error(st, STATUS_USAGE, "the history has "//int_str(session%res%nsteps)//" steps")
         else
            out_out(1:session%res%nsteps) = column
         end if
      end if
      femcod_history = finish(session, st)
   end function femcod_history

   ! ---- helpers ----

   !> The session behind `handle`; false (and no session) for NULL.
   logical function session_of(handle, session)
      type(c_ptr), intent(in) :: handle
      type(library_session), pointer, intent(out) :: session
      session => null()
      session_of = c_associated(handle)
      if (session_of) call c_f_pointer(handle, session)
   end function session_of

   !> True when no address in `addresses` is NULL.
   logical function all_given(addresses)
      type(c_ptr), intent(in) :: addresses(:)
      integer :: k
      all_given = .true.
      do k = 1, size(addresses)
         if (.not. c_associated(addresses(k))) all_given = .false.
      end do
   end function all_given

   !> A call with a NULL where an output goes: STATUS_USAGE, and the session's message
   !> (where there is a session) names the function and its outputs.
   integer(c_int) function null_argument(handle, function_name, outputs)
      type(c_ptr), intent(in) :: handle
      character(len=*), intent(in) :: function_name, outputs
      type(library_session), pointer :: session
      null_argument = STATUS_USAGE
      if (.not. session_of(handle, session)) return
      session%message = function_name//": NULL given where its output goes ("//outputs//"); nothing was written"
   end function null_argument

   !> A state index within the last solve.
   subroutine check_state(session, k, st)
      type(library_session), intent(in) :: session
      integer, intent(in) :: k
      type(status_type), intent(inout) :: st
      if (.not. session%solved) then
         call set_error(st, STATUS_USAGE, "no result: solve first")
      else if (k < 1 .or. k > size(session%res%states)) then
         call set_error(st, STATUS_USAGE, "state "//int_str(k)//" does not exist (1 to "// &
            int_str(size(session%res%states))//")")
      end if
   end subroutine check_state

   !> A new problem makes the last result stale.
   subroutine forget_problem(session)
      type(library_session), intent(inout) :: session
      type(contact_problem) :: none
      session%previous = session%problem
      session%had_problem = session%has_problem
      session%was_solved = session%solved
      session%has_problem = .false.
      session%solved = .false.
      session%problem = none
   end subroutine forget_problem

   integer(c_int) function finish_problem(session, st)
      type(library_session), intent(inout) :: session
      type(status_type), intent(in) :: st
      type(contact_problem) :: none
      session%has_problem = st%code == 0
      if (st%code /= 0) then
         ! The failed set changes nothing: the problem before it, and its result, stay.
         session%problem = session%previous
         session%has_problem = session%had_problem
         session%solved = session%was_solved
      end if
      session%previous = none
      finish_problem = finish(session, st)
   end function finish_problem

   !> The status as a return code, its message kept in the session.
   integer(c_int) function finish(session, st)
      type(library_session), intent(inout) :: session
      type(status_type), intent(in) :: st
      finish = st%code
      session%message = ""
      if (st%code /= 0) session%message = st%message
   end function finish

   !> A NUL-terminated C string as Fortran text (at most MAX_C_STRING characters).
   function from_c(text) result(s)
      character(kind=c_char), intent(in) :: text(*)
      character(len=:), allocatable :: s
      integer :: n, k
      n = 0
      do while (n < MAX_C_STRING)
         if (text(n + 1) == c_null_char) exit
         n = n + 1
      end do
      allocate(character(len=n) :: s)
      do k = 1, n
         s(k:k) = text(k)
      end do
   end function from_c

   !> Copy `s` into a C buffer of `length` bytes, NUL-terminated; 2 (usage) when it does
   !> not fit (the buffer then holds as much as fits).
   integer(c_int) function copy_out(s, text, length)
      character(len=*), intent(in) :: s
      character(kind=c_char), intent(out) :: text(*)
      integer(c_size_t), intent(in) :: length
      integer :: n, k
      copy_out = 0
      if (length < 1) then
         copy_out = STATUS_USAGE
         return
      end if
      n = len(s)
      if (int(n, c_size_t) >= length) then
         n = int(length) - 1
         copy_out = STATUS_USAGE
      end if
      do k = 1, n
         text(k) = s(k:k)
      end do
      text(n + 1) = c_null_char
   end function copy_out

   !> A C-order NP x NP array (a[i*np + j] is row i, column j) as the map (i, j): the one
   !> copy of a caller's heights into the problem.
   function c_order(a, np) result(map)
      real(c_double), intent(in) :: a(*)
      integer, intent(in) :: np
      real(dp), allocatable :: map(:, :)
      integer :: i, j
      allocate(map(np, np))
      do i = 1, np
         do j = 1, np
            map(i, j) = a((i - 1)*np + j)
         end do
      end do
   end function c_order

   !> The map (i, j) into a C-order array.
   subroutine to_c_order(map, a)
      real(dp), intent(in) :: map(:, :)
      real(c_double), intent(out) :: a(:)
      integer :: i, j, np
      np = size(map, 1)
      do i = 1, np
         do j = 1, np
            a((i - 1)*np + j) = map(i, j)
         end do
      end do
   end subroutine to_c_order
end module femcod_capi
