!> What a run asks of a solver: the options every solver takes, and each solver's own
!> (the incremental solver's event search, the cg solver's tolerance and accelerations).
!> `femcod run` fills one `contact_options` from its command line; solvers/femcod_solver
!> dispatches on `solver`.
module femcod_solver_options
   use femcod_kinds, only: dp, i8
   use femcod_memory, only: memory_text, usable_text
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_NUMERICAL
   use femcod_strings, only: format_real, int_str, sig_str, parse_real, parse_integer, parse_real_list
   use femcod_interface_law, only: LAW_HARD_WALL, LAW_DUGDALE, LAW_EXPONENTIAL, law_from_name, law_name
   use femcod_shear_model, only: shear_model, make_shear_model
   implicit none
   private
   public :: contact_options, cg_settings, SOLVER_NAMES, BOUNDARY_NAMES, requested_states
   public :: SOLVER_INCREMENTAL, SOLVER_LEGACY, SOLVER_CG, BOUNDARY_FREE, BOUNDARY_PERIODIC, solver_name, &
      solver_from_name, boundary_name, boundary_from_name
   public :: LAW_HARD_WALL, LAW_DUGDALE, LAW_EXPONENTIAL, law_from_name, law_name
   public :: validate_options, by_gap_variables, history_options, first_difference, tolerance_floor
   public :: OPTION_NAMES, OPTION_KEYS, IN_HISTORY, option_field
   public :: refuse_beyond_memory, run_shear_model

   !> The options of a run, one row each: OPTION_NAMES(k), the option's name on `femcod
   !> run`'s command line ("" for a field that follows from others: shear, tangential and
   !> by_slip are set with their groups' options; tie_tolerance has none); OPTION_KEYS(k),
   !> its field's name; IN_HISTORY(k), whether it shapes the answer (history_options
   !> writes those fields, in this order; the C and Python libraries take those options).
   !> option_field reads and sets each field. A new solver option is its field in
   !> contact_options, a row here, a case in option_field, and its help row in femcod
   !> run's table; run's settings, the history, the checkpoint's record, the fingerprint
   !> and the libraries' names follow.
   character(len=*), parameter :: OPTION_NAMES(*) = [character(len=21) :: "--solver", "--boundary", "--loads", &
      "--approach", "--max-contacts", "--plastic", "--hardness", "--adhesion", "--work", "--range", "", &
      "--no-final-check", "--event-search", "--tol", "--max-iterations", "--kernel-radius", "", "--shear-strength", &
      "--shear-slope", "", "", "--friction", "--tangential", "--slip", "--tangential-tol", "--checkpoint-interval"]
   character(len=*), parameter :: OPTION_KEYS(*) = [character(len=19) :: "solver", "boundary", "loads", &
      "approaches", "max_contacts", "plastic", "hardness", "adhesion", "work", "range", "tie_tolerance", &
      "final_check", "event_search", "tol", "max_iterations", "kernel_radius", "shear", "shear_strength", &
      "shear_slope", "tangential", "by_slip", "friction", "tangential_load", "slip", "tangential_tol", &
      "checkpoint_interval"]
   !> Every field shapes the answer but the checkpoints' interval.
   logical, parameter :: IN_HISTORY(*) = OPTION_KEYS /= "checkpoint_interval"

   !> The solvers: the event-exact incremental solver, the Appendix B program, and the
   !> fixed-load constrained conjugate gradients. An enumeration, with the names the
   !> command line gives them (SOLVER_NAMES(code)), read once at the edge
   !> (solver_from_name).
   integer, parameter :: SOLVER_INCREMENTAL = 1, SOLVER_LEGACY = 2, SOLVER_CG = 3
   character(len=*), parameter :: SOLVER_NAMES(3) = [character(len=11) :: "incremental", "legacy", "cg"]

   !> The lateral boundary: the thesis' half-space with the grid alone on it (free), or
   !> the grid as one cell of a surface that repeats in both directions (periodic). An
   !> enumeration, as the solvers.
   integer, parameter :: BOUNDARY_FREE = 1, BOUNDARY_PERIODIC = 2
   character(len=*), parameter :: BOUNDARY_NAMES(2) = [character(len=8) :: "free", "periodic"]

   !> The cg solver's own options (solvers/femcod_cg). The accelerations default to on;
   !> each can be switched off.
   type :: cg_settings
      !> Stop when the relative complementarity residual (the largest gap violation over
      !> the height range) is below `tol`, or after `max_iterations` on the finest grid.
      real(dp) :: tol = 1.0e-8_dp
      integer :: max_iterations = 2000
      !> Start the first load from nested coarser grids (down to `coarsest` pixels a side).
      logical :: nested = .true.
      integer :: coarsest = 64
      !> Relative residual to which the coarser grids are solved.
      real(dp) :: coarse_tol = 1.0e-4_dp
      !> float32 transforms while the residual is above this (0: never).
      real(dp) :: single_until = 1.0e-5_dp
      !> Precondition the search direction with the 13-point stencil of the inverse Love
      !> operator (a discrete |q|), applied on the contact set.
      logical :: precondition = .true.
      !> Restart the conjugate directions (beta = 0) after overlapping pixels enter the
      !> contact, as Polonsky and Keer do (off: keep them; at NP = 2048 on: 97 instead of
      !> 43 iterations at 1 %, 302 instead of 69 at 10 %, doc/performance.md).
      logical :: restart_on_entry = .false.
      !> beta by Polak-Ribiere, clipped at 0 (PR+: z.(g - g_old)/(z_old.g_old)), which
      !> restarts by itself when the contact set has moved the gradient; off: Fletcher-
      !> Reeves (z.g/(z_old.g_old)), as Polonsky and Keer.
      logical :: polak_ribiere = .true.
      !> Powell's restart (1977): beta = 0 when successive gradients are far from
      !> orthogonal, |z.g_old| >= powell_restart * z.g (z the preconditioned gradient);
      !> 0: never. It stops the contact set's swings after the coarse start on large grids
      !> (NP = 4096, 10 %: 99 instead of 141 iterations, doc/performance.md).
      real(dp) :: powell_restart = 0.2_dp
      !> With the preconditioner, an overlapping pixel enters with entry_scale times the
      !> force the preconditioned step gives a pixel alone (-tau a00 g, a00 the stencil's
      !> centre). A quarter of it churns the contact set less after the coarse start
      !> (pixels entering too strongly leave again): 386 -> 358 iterations over nine
      !> benchmark cases at NP 512 to 2048, 52 -> 44 at 4096^2, 1 % (doc/performance.md).
      real(dp) :: entry_scale = 0.25_dp
      !> Largest number of projection changes corrected directly (0 with split_radius = 0:
      !> a fresh convolution every iteration, i.e. two per iteration as in Polonsky and
      !> Keer).
      integer :: direct_corrections = 32
      !> Beyond `direct_corrections`, the projection's changes are added by a split of the
      !> kernel (femcod_split_correction: a lattice of `split_cell` pixels for the far
      !> part, the exact kernel within a window of up to `split_radius` pixels around each
      !> change) instead of a fresh convolution, while the near part costs at most
      !> `split_budget` NP^2 multiply-adds (the window shrinks with more changes, down to
      !> split_cell) and the error bound these corrections add up to since the last fresh
      !> convolution stays below `split_tolerance` times the residual (in nm: r times the
      !> height range). split_radius = 0: off. Not for periodic grids nor a truncated
      !> kernel. At NP = 4096, 1 %: 31 -> 6 fresh convolutions, 23.4 -> 18.5 s
      !> (doc/performance.md).
      integer :: split_radius = 32
      integer :: split_cell = 8
      real(dp) :: split_budget = 10
      real(dp) :: split_tolerance = 1
      !> Let FFTW time its plans (FFTW_MEASURE) instead of estimating them; worth it
      !> with a wisdom file (`femcod run --fftw-wisdom`), which keeps the plans.
      logical :: measure_plans = .false.
      !> The Love kernel truncated beyond this many pixels (0: the whole kernel): an
      !> approximation whose error the thesis left open (section 5.2.2 iii) and `femcod
      !> bench frontier` measures. The convolution stays an FFT (same cost).
      real(dp) :: kernel_radius = 0
   end type cg_settings

   !> The options of a run. Units: nN, GPa, s.
   type :: contact_options
      !> SOLVER_INCREMENTAL (default), SOLVER_LEGACY or SOLVER_CG.
      integer :: solver = SOLVER_INCREMENTAL
      !> BOUNDARY_FREE (default) or BOUNDARY_PERIODIC (femcod_love_periodic).
      integer :: boundary = BOUNDARY_FREE
      !> Stop after this many contacts, in place of the deck's MAXCONT (0: MAXCONT; the event
      !> solvers only).
      integer :: max_contacts = 0
      !> Requested total loads (nN); empty: the event solvers run to MAXCONT.
      real(dp), allocatable :: loads(:)
      !> Requested approaches (nm; displacement control, instead of loads): the state at
      !> each, with the load as the answer, in the order given.
      real(dp), allocatable :: approaches(:)
      !> Hardness (GPa) for the count of pixels above it (thesis polysilicon: 11 GPa).
      real(dp) :: hardness = 11
      !> Elastic-perfectly-plastic interface: each pixel's pressure is capped at
      !> `hardness`; a capped pixel keeps the force H d^2 and interpenetrates (its
      !> plastic displacement). The cg solver only.
      logical :: plastic = .false.
      !> The interface law (model/femcod_interface_law): LAW_HARD_WALL (no adhesion,
      !> default), LAW_DUGDALE or LAW_EXPONENTIAL, with the work of adhesion (nN/nm =
      !> J/m^2) and the range (nm) of the law. With --approach and the cg solver only.
      integer :: adhesion = LAW_HARD_WALL
      real(dp) :: work = 0, range = 0
      !> Friction from the pressures (model/femcod_shear_model): each contact pixel carries
      !> the shear strength shear_strength + shear_slope p (GPa; capped at H/(3 sqrt 3)
      !> with `plastic`). `shear` false: no friction is computed. Every solver.
      logical :: shear = .false.
      real(dp) :: shear_strength = 0, shear_slope = 0
      !> Tangential loading with Coulomb friction (solvers/femcod_tangential) at every
      !> reached state: the coefficient `friction`, and the tangential force (nN) or, with
      !> `by_slip`, the rigid shift (nm), along x. `tangential` false: none. The step
      !> iterates until its gradient mapping is below `tangential_tol` of the shift.
      logical :: tangential = .false., by_slip = .false.
      real(dp) :: friction = 0, tangential_load = 0, slip = 0, tangential_tol = 1.0e-8_dp
      !> Candidates whose closing load is within this fraction of the total load of the
      !> smallest one join in the same step (ties).
      real(dp) :: tie_tolerance = 1.0e-9_dp
      !> Check every pixel for penetration at the end, and correct (Appendix B).
      logical :: final_check = .true.
      !> Hand the solver state to the observer's checkpoint procedure every this many
      !> seconds of wall time (0: after every step; negative: never). Incremental solver.
      real(dp) :: checkpoint_interval = -1
      !> Incremental solver: how the next event is found: "auto" (the cheaper of the two
      !> by a cost model), "bound" (gap bound and exact evaluations) or "fft" (full field).
      character(len=5) :: event_search = "auto"
      !> The cg solver's own options.
      type(cg_settings) :: cg
      !> The memory the solve may take (bytes): what the machine or the job allows less
      !> what the run holds when it begins, measured by the caller (core/femcod_memory's
      !> available_memory); 0: unknown, not checked. Not part of the answer.
      integer(i8) :: memory_available = 0
      !> cg: free the problem's two height maps (16 bytes a pixel) once the grid holds the
      !> initial gaps, the only form the solve needs. Set by femcod run, which has written
      !> the heights where its results need them before the solve; the problem comes back
      !> without them. Not part of the answer.
      logical :: release_heights = .false.
      !> The observer takes each state's NP x NP maps out of memory as it is solved
      !> (femcod run's writes them to its result file): the storage estimate counts none
      !> kept. Not part of the answer.
      logical :: states_streamed = .false.
   end type contact_options

contains

   !> The solver's name (SOLVER_NAMES), "?" for no solver.
   pure function solver_name(solver) result(name)
      integer, intent(in) :: solver
      character(len=:), allocatable :: name
      name = name_of(solver, SOLVER_NAMES)
   end function solver_name

   !> The solver named `name`; 0 for any other name.
   pure integer function solver_from_name(name) result(solver)
      character(len=*), intent(in) :: name
      solver = code_of(name, SOLVER_NAMES)
   end function solver_from_name

   !> The boundary's name (BOUNDARY_NAMES), "?" for none.
   pure function boundary_name(boundary) result(name)
      integer, intent(in) :: boundary
      character(len=:), allocatable :: name
      name = name_of(boundary, BOUNDARY_NAMES)
   end function boundary_name

   !> The boundary named `name`; 0 for any other name.
   pure integer function boundary_from_name(name) result(boundary)
      character(len=*), intent(in) :: name
      boundary = code_of(name, BOUNDARY_NAMES)
   end function boundary_from_name

   !> names(code) without its blanks; "?" for a code outside the names.
   pure function name_of(code, names) result(name)
      integer, intent(in) :: code
      character(len=*), intent(in) :: names(:)
      character(len=:), allocatable :: name
      if (code >= 1 .and. code <= size(names)) then
         name = trim(names(code))
      else
         name = "?"
      end if
   end function name_of

   !> The position of `name` in `names`; 0 when it is none of them.
   pure integer function code_of(name, names) result(code)
      character(len=*), intent(in) :: name, names(:)
      integer :: k
      code = 0
      do k = 1, size(names)
         if (trim(name) == trim(names(k))) code = k
      end do
   end function code_of

   !> The number of requested states: one per load of --loads or approach of --approach.
   pure integer function requested_states(options)
      type(contact_options), intent(in) :: options
      requested_states = 0
      if (allocated(options%loads)) requested_states = size(options%loads)
      if (allocated(options%approaches)) requested_states = requested_states + size(options%approaches)
   end function requested_states
   !> True when the run is solved in the gap variables under displacement control
   !> (solvers/femcod_gap_cg): --solver cg with --approach and an interface law other
   !> than the elastic hard wall, i.e. --adhesion or --plastic. The plastic interface is
   !> path-dependent and its load is not a function of the approach where the plastic
   !> pixels carry it all (the load stays while the body sinks), so displacement control
   !> solves it directly rather than by loads.
   pure logical function by_gap_variables(options)
      type(contact_options), intent(in) :: options
      by_gap_variables = .false.
      if (options%solver /= SOLVER_CG .or. .not. allocated(options%approaches)) return
      by_gap_variables = size(options%approaches) > 0 .and. (options%adhesion /= LAW_HARD_WALL .or. options%plastic)
   end function by_gap_variables

   !> The one place where the combinations of options are checked: `femcod run` (and
   !> femcod-mpi, which shares its parser) after parsing, before any file is read or any
   !> lock taken, and solve_contact for every library caller, the benchmarks included. A
   !> refused combination names both options (STATUS_USAGE, exit 2). Checks that need the
   !> deck (a load above the fully plastic capacity) are the solvers' own.
   subroutine validate_options(options, status)
      type(contact_options), intent(in) :: options
      type(status_type), intent(inout) :: status
      integer :: nloads, napproaches
      if (status%code /= 0) return
      nloads = 0
      napproaches = 0
      if (allocated(options%loads)) nloads = size(options%loads)
      if (allocated(options%approaches)) napproaches = size(options%approaches)
      if (solver_name(options%solver) == "?") then
         call refuse("unknown solver "//int_str(options%solver)//" (available: incremental, legacy, cg)")
      else if (boundary_name(options%boundary) == "?") then
         call refuse("unknown boundary "//int_str(options%boundary)//" (free or periodic)")
      else if (.not. any([LAW_HARD_WALL, LAW_DUGDALE, LAW_EXPONENTIAL] == options%adhesion)) then
         call refuse("unknown adhesion law "//int_str(options%adhesion)//" (dugdale or exponential)")
      else if (nloads > 0 .and. napproaches > 0) then
         call refuse("give --loads (load control) or --approach (displacement control), not both")
      else if (options%solver == SOLVER_CG .and. nloads + napproaches == 0) then
         call refuse("--solver cg solves at given loads or approaches: add --loads F1,F2,... or --approach D1,D2,...")
      else if (options%plastic .and. options%solver == SOLVER_LEGACY) then
         call refuse("--plastic with --solver legacy: the legacy solver is the Appendix B program of the elastic "// &
            "interface; use --solver incremental or cg")
      else if (options%boundary == BOUNDARY_PERIODIC .and. options%solver == SOLVER_LEGACY) then
         call refuse("--boundary periodic with --solver legacy: the legacy solver is the Appendix B program of the "// &
            "free half-space; use --solver incremental or cg")
      else if (options%adhesion /= LAW_HARD_WALL .and. options%solver /= SOLVER_CG) then
         call refuse("--adhesion with --solver "//solver_name(options%solver)//": the event solvers follow a path of "// &
            "contact events without tension; use --solver cg")
      else if (options%adhesion /= LAW_HARD_WALL .and. napproaches == 0) then
         call refuse("--adhesion needs --approach D1,D2,... (displacement control: under load control the pull-off "// &
            "is an instability)")
      else if (options%shear .and. options%adhesion /= LAW_HARD_WALL) then
         call refuse("--shear-strength/--shear-slope with --adhesion: the shear model gives the friction "// &
            "coefficient F_t/F of a compressive contact; with adhesion the load passes through zero and the "// &
            "contact pixels carry tension")
      else if (options%shear .and. .not. (options%shear_strength >= 0 .and. options%shear_slope >= 0)) then
         call refuse("--shear-strength and --shear-slope are at least 0")
      else if (options%adhesion /= LAW_HARD_WALL .and. .not. (options%work >= 0 .and. options%range > 0)) then
         call refuse("--adhesion needs --work W >= 0 (J/m^2) and --range R > 0 (nm)")
      else if (options%solver == SOLVER_CG .and. options%cg%tol < tolerance_floor()) then
         call refuse("--tol "//sig_str(options%cg%tol, 3)//" is below what double precision resolves: the "// &
            "gaps are sums of terms as large as the height range, each rounded to 1.1e-16 of it, so a relative "// &
            "violation below 10 machine epsilons ("//sig_str(tolerance_floor(), 2)//") cannot be shown; give "// &
            "--tol "//sig_str(tolerance_floor(), 2)//" or more")
      else if (options%boundary == BOUNDARY_PERIODIC .and. options%cg%kernel_radius > 0) then
         call refuse("--kernel-radius with --boundary periodic: the periodic kernel is a sum over every image "// &
            "of the cell, and cutting it changes the cell's mean compliance (on a 32-pixel cell R = 16 gave an "// &
            "approach 28 % short); use the whole periodic kernel, or --kernel-radius on the free surface")
      else if (options%plastic .and. nloads > 1) then
         if (any(options%loads(2:) < options%loads(:nloads - 1))) call refuse("--loads with --plastic: the "// &
            "plastic interface remembers its path and the fixed-load solves only load; give the loads in "// &
            "increasing order, or unload by displacement control (--solver cg --approach D1,D2,...)")
      else if (options%plastic .and. options%solver /= SOLVER_CG .and. napproaches > 1) then
         if (any(options%approaches(2:) < options%approaches(:napproaches - 1))) call refuse("--approach with "// &
            "--plastic and --solver "//solver_name(options%solver)//": the event path only loads; give the approaches in "// &
            "increasing order, or unload with --solver cg")
      end if
      if (status%code == 0 .and. options%tangential) call refuse_tangential(options, status)
   contains
      subroutine refuse(message)
         character(len=*), intent(in) :: message
         call set_error(status, STATUS_USAGE, message)
      end subroutine refuse
   end subroutine validate_options
   !> The options that shape a run's answer, as "key=value" fields joined by "; ", in the
   !> order of OPTION_KEYS: what a checkpoint stores and --restart compares whole, and
   !> what the run's fingerprint digests (a finished run's --restart). Progress,
   !> checkpoint and speed settings are not in it (IN_HISTORY false).
   function history_options(options) result(text)
      type(contact_options), intent(in) :: options
      character(len=:), allocatable :: text, value
      type(contact_options) :: copy
      integer :: k
      text = ""
      copy = options
      do k = 1, size(OPTION_KEYS)
         if (.not. IN_HISTORY(k)) cycle
         call option_field(copy, k, value, .false.)
         if (len(text) > 0) text = text//"; "
         text = text//trim(OPTION_KEYS(k))//"="//value
      end do
   end function history_options

   !> Row k of the option table: with `set`, its field set from `text` as the command line
   !> gives it (a flag's text is ignored: given means set; the parser checked the value);
   !> otherwise `text` the field's value as history_options writes it.
   subroutine option_field(o, k, text, set)
      type(contact_options), intent(inout) :: o
      integer, intent(in) :: k
      character(len=:), allocatable, intent(inout) :: text
      logical, intent(in) :: set
      logical :: ok
      select case (trim(OPTION_KEYS(k)))
      case ("solver"); call choice(o%solver, SOLVER_NAMES)
      case ("boundary"); call choice(o%boundary, BOUNDARY_NAMES)
      case ("loads"); call real_list(o%loads)
      case ("approaches"); call real_list(o%approaches)
      case ("max_contacts"); call whole(o%max_contacts)
      case ("plastic"); call flag(o%plastic, .true.)
      case ("hardness"); call real_value(o%hardness)
      case ("adhesion")
         if (set) o%adhesion = law_from_name(text)
         if (.not. set) text = law_name(o%adhesion)
      case ("work"); call real_value(o%work)
      case ("range"); call real_value(o%range)
      case ("tie_tolerance"); call real_value(o%tie_tolerance)
      case ("final_check"); call flag(o%final_check, .false.)
      case ("event_search")
         if (set) o%event_search = text
         if (.not. set) text = trim(o%event_search)
      case ("tol"); call real_value(o%cg%tol)
      case ("max_iterations"); call whole(o%cg%max_iterations)
      case ("kernel_radius"); call real_value(o%cg%kernel_radius)
      case ("shear"); call flag(o%shear, .true.)
      case ("shear_strength"); call real_value(o%shear_strength, o%shear)
      case ("shear_slope"); call real_value(o%shear_slope, o%shear)
      case ("tangential"); call flag(o%tangential, .true.)
      case ("by_slip"); call flag(o%by_slip, .true.)
      case ("friction"); call real_value(o%friction)
      case ("tangential_load"); call real_value(o%tangential_load, o%tangential)
      case ("slip"); call real_value(o%slip, o%tangential, o%by_slip)
      case ("tangential_tol"); call real_value(o%tangential_tol)
      case ("checkpoint_interval"); call real_value(o%checkpoint_interval)
      end select
   contains
      !> A real; given, it also sets the group flags it implies.
      subroutine real_value(x, implied, implied2)
         real(dp), intent(inout) :: x
         logical, intent(inout), optional :: implied, implied2
         if (.not. set) then
            text = format_real(x)
            return
         end if
         call parse_real(text, x, ok)
         if (present(implied)) implied = .true.
         if (present(implied2)) implied2 = .true.
      end subroutine real_value
      subroutine whole(n)
         integer, intent(inout) :: n
         if (set) call parse_integer(text, n, ok)
         if (.not. set) text = int_str(n)
      end subroutine whole
      !> A flag: given, the field takes `given`.
      subroutine flag(x, given)
         logical, intent(inout) :: x
         logical, intent(in) :: given
         if (set) x = given
         if (.not. set) text = merge("T", "F", x)
      end subroutine flag
      subroutine choice(code, names)
         integer, intent(inout) :: code
         character(len=*), intent(in) :: names(:)
         if (set) code = code_of(text, names)
         if (.not. set) text = name_of(code, names)
      end subroutine choice
      subroutine real_list(v)
         real(dp), allocatable, intent(inout) :: v(:)
         integer :: m
         if (set) then
            call parse_real_list(text, v, ok)
            return
         end if
         text = ""
         if (.not. allocated(v)) return
         do m = 1, size(v)
            if (m > 1) text = text//","
            text = text//format_real(v(m))
         end do
      end subroutine real_list
   end subroutine option_field

   !> What a tangential step (`tangential`) is refused with: a friction coefficient that is
   !> not positive, a load or shift below zero, adhesion (tension in the contact: no
   !> Coulomb bound).
   subroutine refuse_tangential(options, status)
      type(contact_options), intent(in) :: options
      type(status_type), intent(inout) :: status
      if (.not. options%friction > 0) then
         call set_error(status, STATUS_USAGE, "--tangential Q and --slip S need --friction MU > 0 (the Coulomb "// &
            "coefficient)")
      else if (.not. (options%tangential_load >= 0 .and. options%slip >= 0)) then
         call set_error(status, STATUS_USAGE, "--tangential Q and --slip S are at least 0 (along x)")
      else if (.not. (options%tangential_tol > 0 .and. options%tangential_tol < 1)) then
         call set_error(status, STATUS_USAGE, "--tangential-tol T is a relative residual: 0 < T < 1")
      else if (options%adhesion /= LAW_HARD_WALL) then
         call set_error(status, STATUS_USAGE, "--tangential/--slip with --adhesion: the Coulomb bound mu p needs a "// &
            "compressive contact, and adhesive contacts carry tension")
      end if
   end subroutine refuse_tangential

   !> The run's shear model (inactive without `shear`).
   pure function run_shear_model(options) result(model)
      type(contact_options), intent(in) :: options
      type(shear_model) :: model
      if (options%shear) model = make_shear_model(options%shear_strength, options%shear_slope, options%plastic, &
         options%hardness)
   end function run_shear_model

   !> The first field in which two history_options texts differ, as "name=A there,
   !> name=B here" ("" when they are equal).
   function first_difference(there, here) result(text)
      character(len=*), intent(in) :: there, here
      character(len=:), allocatable :: text
      integer :: a, b, ea, eb
      text = ""
      if (there == here) return
      a = 1
      b = 1
      do
         ea = index(there(a:), "; ")
         eb = index(here(b:), "; ")
         if (ea == 0) ea = len(there) - a + 2
         if (eb == 0) eb = len(here) - b + 2
         if (there(a:a + ea - 2) /= here(b:b + eb - 2)) then
            text = there(a:a + ea - 2)//" there, "//here(b:b + eb - 2)//" here"
            return
         end if
         a = a + ea + 1
         b = b + eb + 1
         if (a > len(there) .or. b > len(here)) exit
      end do
      text = "the option sets differ in length"
   end function first_difference
   !> A solver's storage `need` (bytes) against the memory the solve may take (0:
   !> unknown, not checked): STATUS_NUMERICAL (exit 4) with both figures, before anything
   !> is allocated. `what` names the solver and the grid.
   subroutine refuse_beyond_memory(what, need, available, status)
      character(len=*), intent(in) :: what
      integer(i8), intent(in) :: need, available
      type(status_type), intent(inout) :: status
      if (available > 0 .and. need > available) call set_error(status, STATUS_NUMERICAL, what//" needs about "// &
         memory_text(need)//" for the solver's arrays, this run may give it "//usable_text(available)// &
         " (the memory it may use less what it holds); femcod-mpi splits a grid over nodes")
   end subroutine refuse_beyond_memory

   !> The smallest --tol the cg solvers accept: 10 machine epsilons of double precision
   !> (2.2e-16 each). Their residual is a gap violation over the height range; a gap is
   !> g0 - A + u, terms as large as the range, each rounded to half an epsilon of it.
   pure real(dp) function tolerance_floor()
      tolerance_floor = 10*epsilon(1.0_dp)
   end function tolerance_floor
end module femcod_solver_options
