!> What a library caller holds between calls (capi/femcod_capi): the problem, the
!> options given by name, and the result of the last solve with its maps. The solve goes
!> through `femcod run`'s own parser and rules (cli/femcod_run_options' parse_run_arguments) and
!> the one solver interface, so a combination the command refuses is refused here with
!> the same words, and an answer is the command's to the last bit.
module femcod_library_session
   use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_funptr, c_null_ptr, c_associated, &
      c_f_procpointer
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_INTERRUPTED
   use femcod_strings, only: string_type, int_str
   use femcod_clock, only: wall_clock
   use femcod_memory, only: available_memory
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result, state_values, cg_work, cg_state_diagnostics
   use femcod_result_schema, only: run_info
   use femcod_state_record, only: state_field, state_fields, run_info_for, FIELD_COUNT, FIELD_FLAG
   use femcod_solver_options, only: contact_options, BOUNDARY_PERIODIC, OPTION_NAMES, IN_HISTORY
   use femcod_observer, only: solver_observer
   use femcod_solver, only: solve_contact, run_warnings
   use femcod_maps, only: load_maps, state_maps, tangential_step_maps, state_pressure_map
   use femcod_options, only: parsed_options, parse_options
   use femcod_run_options, only: run_table, run_settings, parse_run_arguments
   implicit none
   private
   public :: library_session, solve_session, state_value, state_value_names, state_value_kinds, map_of, map_names, &
      history_column, HISTORY_COLUMNS, library_options

   !> The history's columns (femcod_history).
   character(len=*), parameter :: HISTORY_COLUMNS = "step,contacts,load_nN,approach_nm,area_nm2,area_fraction,"// &
      "n_above_hardness"
   !> The least interval between two calls of the caller's progress function while a
   !> solver iterates (s).
   real(dp), parameter :: CALLBACK_INTERVAL = 0.1_dp

   !> One caller's problem, options and last result.
   type :: library_session
      type(contact_problem) :: problem
      logical :: has_problem = .false.
      !> The problem (and whether a result went with it) while a new one is being set: a
      !> set that fails puts it back, so a bad call loses nothing.
      type(contact_problem) :: previous
      logical :: had_problem = .false., was_solved = .false.
      !> The options as `femcod run` takes them: names and values in order.
      type(string_type), allocatable :: args(:)
      !> The last solve: its options, result and maps (solved: they hold one).
      type(contact_options) :: options
      type(contact_result) :: res
      type(state_maps), allocatable :: maps(:)
      !> The run record of the last solve (which state values it has, kappa's scales).
      type(run_info) :: info
      logical :: solved = .false.
      !> The message of the last failure; what the last read of heights warned of.
      character(len=:), allocatable :: message, warnings
   end type library_session

   abstract interface
      !> The caller's progress function: non-zero stops the solve.
      integer(c_int) function progress_function(step, contacts, load, seconds, user) bind(C)
         import :: c_int, c_double, c_ptr
         integer(c_int), value :: step, contacts
         real(c_double), value :: load, seconds
         type(c_ptr), value :: user
      end function progress_function
   end interface

   !> Hands the solver's progress to the caller's function, which may ask it to stop.
   type, extends(solver_observer) :: library_observer
      procedure(progress_function), pointer, nopass :: callback => null()
      type(c_ptr) :: user = c_null_ptr
      integer :: step = 0, contacts = 0
      real(dp) :: load = 0, started = 0, last_call = 0
      logical :: stopped = .false.
   contains
      procedure :: progress => tell_progress
      procedure :: stop_requested => caller_stops
      procedure :: call_back
   end type library_observer

contains

   !> Solve the session's problem with its options; the result and its maps replace the
   !> last ones (none are kept after a failure).
   subroutine solve_session(session, progress, user, st)
      type(library_session), intent(inout) :: session
      type(c_funptr), intent(in) :: progress
      type(c_ptr), intent(in) :: user
      type(status_type), intent(inout) :: st
      type(run_settings) :: settings
      type(library_observer) :: observer
      type(contact_options) :: options
      type(contact_result) :: empty
      type(string_type), allocatable :: warnings(:)
      integer :: k
      session%solved = .false.
      session%warnings = ""
      session%res = empty
      if (allocated(session%maps)) deallocate(session%maps)
      if (.not. session%has_problem) then
         call set_error(st, STATUS_USAGE, "no problem: set one or read a deck first")
         return
      end if
      call refuse_file_options(session%args, st)
      if (st%code /= 0) return
      ! run's parser wants a deck: a stand-in name, never opened.
      call parse_run_arguments([session%args, string_type("arrays")], settings, st)
      if (st%code /= 0) return
      options = settings%solve
      options%checkpoint_interval = -1
      options%memory_available = available_memory()
      if (c_associated(progress)) call c_f_procpointer(progress, observer%callback)
      observer%user = user
      call wall_clock(observer%started)
      observer%last_call = observer%started
      call solve_contact(session%problem, options, session%res, st, observer)
      if (observer%stopped .and. st%code == STATUS_INTERRUPTED) st%message = "stopped by the progress function"
      if (st%code /= 0) then
         session%res = empty
         return
      end if
      call load_maps(session%problem, session%res%states, session%maps, options%boundary == BOUNDARY_PERIODIC)
      session%options = options
      session%info = run_info_for(session%problem, options)
      session%solved = .true.
      ! What `femcod run` prints as warnings (a requested state not reached, a tangential
      ! step without contact): femcod_warnings, one per line.
      warnings = run_warnings(options, session%res)
      session%warnings = ""
      do k = 1, size(warnings)
         session%warnings = session%warnings//warnings(k)%s//new_line("a")
      end do
   end subroutine solve_session

   !> Refuse run's options that are not the solver's (library_options), with the reason,
   !> and a value given where none belongs (a flag's "value": a stray argument). The
   !> arguments are parsed by run's own parser, which reports unknown options itself.
   subroutine refuse_file_options(args, st)
      type(string_type), intent(in) :: args(:)
      type(status_type), intent(inout) :: st
      type(parsed_options) :: parsed
      integer :: k
      call parse_options(run_table(), args, parsed, st)
      if (st%code /= 0) return
      do k = 1, size(parsed%table)
         if (parsed%given(k) .and. index(" "//library_options()//" ", " "//parsed%table(k)%name//" ") == 0) then
            call set_error(st, STATUS_USAGE, parsed%table(k)%name//" is an option of the femcod command, not of the "// &
               "library: the caller gives the arrays and keeps the results (library options: "// &
               library_options()//")")
            return
         end if
      end do
      if (size(parsed%positional) > 0) call set_error(st, STATUS_USAGE, "'"//parsed%positional(1)%s// &
         "' follows no option that takes a value (a flag such as --plastic takes none)")
   end subroutine refuse_file_options

   !> `femcod run`'s options that a library call takes, separated by spaces: those that
   !> shape the answer (IN_HISTORY). The others name files, the run's printing or its
   !> checkpoints, or build the scene from files (the library's caller gives the arrays).
   function library_options() result(text)
      character(len=:), allocatable :: text
      integer :: k
      text = ""
      do k = 1, size(OPTION_NAMES)
         if (len_trim(OPTION_NAMES(k)) == 0 .or. .not. IN_HISTORY(k)) cycle
         if (len(text) > 0) text = text//" "
         text = text//trim(OPTION_NAMES(k))
      end do
   end function library_options

   !> The names of the state values the last solve has (comma-separated): whether the
   !> state was reached, then its fields (io/femcod_state_record, as in PREFIX.h5).
   function state_value_names(session) result(names)
      type(library_session), intent(in) :: session
      character(len=:), allocatable :: names
      names = value_list(session, .false.)
   end function state_value_names

   !> The kinds of the state values, in the order of state_value_names: "number",
   !> "count" (an integer) or "flag" (1 or 0; `reached` first).
   function state_value_kinds(session) result(kinds)
      type(library_session), intent(in) :: session
      character(len=:), allocatable :: kinds
      kinds = value_list(session, .true.)
   end function state_value_kinds

   !> `reached`, then the field table's names (or, with `kinds`, their kinds), by commas.
   function value_list(session, kinds) result(list)
      type(library_session), intent(in) :: session
      logical, intent(in) :: kinds
      character(len=:), allocatable :: list
      type(state_field), allocatable :: f(:)
      integer :: m
      f = state_fields(state_values(), session%problem%pixel, max(session%problem%np, 1), &
         session%info, cg_state_diagnostics())
      list = trim(merge("flag   ", "reached", kinds))
      do m = 1, size(f)
         if (.not. kinds) then
            list = list//","//f(m)%name
         else if (f(m)%kind == FIELD_COUNT) then
            list = list//",count"
         else if (f(m)%kind == FIELD_FLAG) then
            list = list//",flag"
         else
            list = list//",number"
         end if
      end do
   end function value_list

   !> State k's value `name` (as femcod run's PREFIX.h5 has it; 1 or 0 for a flag).
   subroutine state_value(session, k, name, value, st)
      type(library_session), intent(in) :: session
      integer, intent(in) :: k
      character(len=*), intent(in) :: name
      real(c_double), intent(out) :: value
      type(status_type), intent(inout) :: st
      type(state_field), allocatable :: f(:)
      integer :: m
      value = 0
      if (name == "reached") then
         value = merge(1, 0, session%res%states(k)%reached)
         return
      end if
      f = state_fields(session%res%states(k)%state_values, session%problem%pixel, session%problem%np, session%info, &
         cg_work(session%res, k))
      do m = 1, size(f)
         if (f(m)%name == name) then
            value = f(m)%value
            return
         end if
      end do
      call set_error(st, STATUS_USAGE, "no state value '"//name//"' in this result (it has: "// &
         state_value_names(session)//")")
   end subroutine state_value

   !> The names of the maps the last solve has.
   function map_names(session) result(names)
      type(library_session), intent(in) :: session
      character(len=:), allocatable :: names
      names = "pressure,gap"
      if (session%options%plastic) names = names//",plastic_displacement"
      if (session%options%tangential) names = names//",shear_x,shear_y,stick,slip"
   end function map_names

   !> State k's map `name` (NP x NP, (i, j) row i column j).
   subroutine map_of(session, k, name, map, st)
      type(library_session), intent(in) :: session
      integer, intent(in) :: k
      character(len=*), intent(in) :: name
      real(dp), allocatable, intent(out) :: map(:, :)
      type(status_type), intent(inout) :: st
      if (.not. session%res%states(k)%reached) then
         call set_error(st, STATUS_USAGE, "state "//int_str(k)//" was not reached: it has no maps")
         return
      end if
      select case (name)
      case ("pressure")
         map = state_pressure_map(session%problem%np, session%problem%pixel, session%res%states(k))
      case ("gap")
         map = session%maps(k)%gap
      case ("plastic_displacement")
         if (allocated(session%res%states(k)%plastic)) map = session%res%states(k)%plastic
      case ("shear_x", "shear_y", "stick", "slip")
         if (session%options%tangential) map = tangential_map(findloc(["shear_x", "shear_y", "stick  ", &
            "slip   "], name, 1))
      end select
      if (.not. allocated(map)) call set_error(st, STATUS_USAGE, "no map '"//name//"' in this result (it has: "// &
         map_names(session)//")")
   contains
      !> One of the tangential step's maps, as femcod run's PREFIX.h5 has it.
      function tangential_map(which) result(m)
         integer, intent(in) :: which
         real(dp), allocatable :: m(:, :)
         real(dp), allocatable :: all(:, :, :)
         all = tangential_step_maps(session%problem%np, session%problem%pixel, session%res%states(k))
         m = all(:, :, which)
      end function tangential_map
   end subroutine map_of

   !> A column of the history by name (HISTORY_COLUMNS), as femcod run's history.csv.
   subroutine history_column(session, name, column, st)
      type(library_session), intent(in) :: session
      character(len=*), intent(in) :: name
      real(dp), allocatable, intent(out) :: column(:)
      type(status_type), intent(inout) :: st
      integer :: n, k
      real(dp) :: area_pixel, region
      n = session%res%nsteps
      area_pixel = session%problem%pixel**2
      region = session%problem%np**2*area_pixel
      associate(r => session%res)
         select case (name)
         case ("step"); column = [(real(k, dp), k = 1, n)]
         case ("contacts"); column = real(r%step_contacts(1:n), dp)
         case ("load_nN"); column = r%step_load(1:n)
         case ("approach_nm"); column = r%step_approach(1:n)
         case ("area_nm2"); column = r%step_contacts(1:n)*area_pixel
         case ("area_fraction"); column = r%step_contacts(1:n)*area_pixel/region
         case ("n_above_hardness"); column = real(r%step_above_hardness(1:n), dp)
         case default
            call set_error(st, STATUS_USAGE, "no history column '"//name//"' (columns: "//HISTORY_COLUMNS//")")
         end select
      end associate
   end subroutine history_column

   ! ---- the observer ----

   subroutine tell_progress(self, step, contacts, load, elapsed)
      class(library_observer), intent(inout) :: self
      integer, intent(in) :: step, contacts
      real(dp), intent(in) :: load, elapsed
      self%step = step
      self%contacts = contacts
      self%load = load
      call self%call_back()
   end subroutine tell_progress

   logical function caller_stops(self)
      class(library_observer), intent(inout) :: self
      real(dp) :: now
      if (.not. self%stopped .and. associated(self%callback)) then
         call wall_clock(now)
         if (now - self%last_call >= CALLBACK_INTERVAL) call self%call_back()
      end if
      caller_stops = self%stopped
   end function caller_stops

   !> Call the caller's function with the last progress; a non-zero answer stops.
   subroutine call_back(self)
      class(library_observer), intent(inout) :: self
      real(dp) :: now
      if (.not. associated(self%callback)) return
      call wall_clock(now)
      self%last_call = now
      if (self%callback(int(self%step, c_int), int(self%contacts, c_int), real(self%load, c_double), &
         real(now - self%started, c_double), self%user) /= 0) self%stopped = .true.
   end subroutine call_back
end module femcod_library_session
