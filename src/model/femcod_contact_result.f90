!> What a contact solver returns: the step history, the states at requested loads,
!> the contact pixels with their forces (the common result, the same for every solver),
!> and each solver's own account of its work and checks, a type that extends
!> solver_diagnostics: event_path_diagnostics (incremental), legacy_diagnostics (the
!> Appendix B program: the event path's checks and TRFACT's conditioning) and
!> cg_diagnostics (per state: iterations, residuals, the approach's error bound).
module femcod_contact_result
   use femcod_kinds, only: dp, i8
   use femcod_arrays, only: grow
   use femcod_state_visitor, only: state_visitor
   use femcod_strings, only: int_str
   use femcod_shear_model, only: shear_model, friction_force
   implicit none
   private
   public :: contact_result, state_values, load_state, append_step, visit_result, record_approach_states
   public :: solver_diagnostics, event_path_diagnostics, legacy_diagnostics, cg_diagnostics, cg_state_diagnostics, &
      event_checks, legacy_checks, cg_work, visit_event_checks, cg_iterations_in_all, largest_cg_residual
   public :: STOP_MAXCONT, STOP_LOADS, STOP_NO_CONTACT, STOP_INTERRUPTED, stop_reason_text, record_load_states, finish_contacts, &
      gather_contacts

   !> STOP_INTERRUPTED: a stop signal ended the run between two requested states; the
   !> states before it are kept (a partial run), the others not reached.
   integer, parameter :: STOP_MAXCONT = 1, STOP_LOADS = 2, STOP_NO_CONTACT = 3, STOP_INTERRUPTED = 4

   !> One requested state's values, the same for every program that solves it (femcod run,
   !> femcod-mpi, the C and Python libraries): what the result files write of a state.
   type :: state_values
      real(dp) :: load = 0, approach = 0
      integer :: contacts = 0
      real(dp) :: max_pressure = 0
      integer :: n_above_hardness = 0
      !> With the plastic cap (--plastic): the pixels at the hardness, and the plastic
      !> volume (nm^3): the sum of the capped pixels' interpenetrations times d^2.
      integer :: n_plastic = 0
      real(dp) :: plastic_volume = 0
      !> With adhesion (--adhesion): the pixels off contact within the law's range
      !> (0 < gap < R: the attractive area), the load off contact (nN, negative: the
      !> adhesive pull outside the contact), the mean gap over the grid
      !> (nm), and a jump from the previous approach's state: 1 into contact (from no
      !> contact), -1 pull-off (to no contact), 0 none.
      integer :: attractive = 0, jump = 0
      real(dp) :: attractive_load = 0, mean_gap = 0
      !> With the shear model (--shear-strength, --shear-slope; model/femcod_shear_model):
      !> the friction force (nN), the sum of tau(p) d^2 over the contacts.
      real(dp) :: friction = 0
      !> With a tangential step (--tangential, --slip; solvers/femcod_tangential): the
      !> contacts' tangential forces (nN, in the order of the contact pixels; on ranks,
      !> this rank's) and whether each sticks, the sticking contacts (of all ranks), the
      !> rigid tangential shift (nm, x and y: the tangential approach) and the total
      !> tangential force (nN), gross sliding (Q >= mu P), and the iteration's count and
      !> relative residual.
      real(dp), allocatable :: shear_x(:), shear_y(:)
      logical, allocatable :: stick(:)
      integer :: stick_contacts = 0
      real(dp) :: tangential_shift(2) = 0, tangential_force(2) = 0
      logical :: sliding = .false.
      integer :: tangential_iterations = 0
      real(dp) :: tangential_residual = 0
      !> The contact patches, 4- and 8-connected (model/femcod_patches; with the maps).
      integer :: patches_4 = 0, patches_8 = 0
      logical :: reached = .false.
   end type state_values

   !> The contact state at one requested load: its values and its contact pixels.
   type, extends(state_values) :: load_state
      !> The contact pixels (row, column) and their forces (nN) at this load.
      integer, allocatable :: i(:), j(:)
      real(dp), allocatable :: force(:)
      !> The gap map (nm, NP x NP, 0 at the contacts) when the solver has it from its last
      !> double-precision convolution (cg); otherwise unallocated and the maps are
      !> computed afterwards (solvers/femcod_maps). Not kept in checkpoints.
      real(dp), allocatable :: gap(:, :)
      !> With the plastic cap: the plastic displacement map (nm, NP x NP; the
      !> interpenetration of the capped pixels, 0 elsewhere).
      real(dp), allocatable :: plastic(:, :)
   end type load_state

   !> What a solver reports of its own work beyond the common result; each solver's
   !> type extends it, and contact_result holds the one its solver made.
   type, abstract :: solver_diagnostics
   end type solver_diagnostics

   !> The event-exact path (incremental solver): what its candidate search found and
   !> what the final checks over all pixels found.
   type, extends(solver_diagnostics) :: event_path_diagnostics
      !> Contacts found late by the candidate search (joined with a penetration), and by
      !> the final check over all pixels.
      integer :: missed_during_run = 0, missed_final_check = 0
      !> Contacts released (force reached zero) during the run.
      integer :: releases = 0
      !> Exact pixel evaluations made by the candidate search.
      integer(i8) :: evaluations = 0
      !> Contacts whose bordering columns came from the candidate cache, contacts that
      !> needed their own triangular solves, cache refills and the columns they made.
      integer :: cache_hits = 0, cache_misses = 0, cache_refills = 0, cache_columns = 0
      !> Steps whose event search used the full-field FFT.
      integer :: fft_steps = 0
      !> Largest relative difference between the accumulated state and an exact
      !> active-set solve at the end (a consistency check of the step accumulation).
      real(dp) :: final_check_difference = 0
      !> Deepest penetration of any pixel not in contact at the end (nm, >= 0), from the
      !> full-field check.
      real(dp) :: max_penetration = 0
   end type event_path_diagnostics

   !> The Appendix B program (legacy solver): the event path's checks, and its skyline
   !> system's conditioning.
   type, extends(event_path_diagnostics) :: legacy_diagnostics
      !> The largest TRFACT pivot loss of the run (about log10 of it digits lost to
      !> cancellation).
      real(dp) :: pivot_loss = 1
      !> The largest 1-norm condition estimate of its skyline system (TRFACT + LAPACK
      !> dlacn2).
      real(dp) :: condition = 0
   end type legacy_diagnostics

   !> The cg solver's work at one state.
   type :: cg_state_diagnostics
      !> Iterations, relative complementarity residual, deepest penetration (nm), largest
      !> |gap| on contact (nm), relative load error.
      integer :: iterations = 0
      real(dp) :: residual = 0, penetration = 0, contact_gap = 0, load_error = 0
      !> At a given load (elastic, full kernel, not periodic): the approach is within
      !> approach_bound (nm) of the exact answer of the discrete problem (femcod_cg's
      !> approach_error_bound); -1 where there is no bound.
      real(dp) :: approach_bound = -1
      !> Iterations on all coarser grids together, fresh convolutions of the forces on
      !> the finest grid, and corrections there by the kernel split instead of a fresh
      !> convolution; with the plastic cap, the rounds of the plastic set.
      integer :: coarse_iterations = 0, convolutions = 0, split_corrections = 0, plastic_rounds = 0
   end type cg_state_diagnostics

   !> The cg solver: its work at each requested state (in the order of the states).
   type, extends(solver_diagnostics) :: cg_diagnostics
      type(cg_state_diagnostics), allocatable :: states(:)
   end type cg_diagnostics

   !> Results of a run. Units: nN, nm, GPa. What continues a run (the history, the
   !> states reached, the counters) is listed once in `visit_result` for checkpoints.
   type :: contact_result
      integer :: nsteps = 0
      !> Per step: contacts carrying load, total load and approach at the end of the step,
      !> and the contacts whose pressure exceeds the hardness there (thesis Fig. 4.21).
      integer, allocatable :: step_contacts(:), step_above_hardness(:)
      !> Per step, the pixels at the hardness (--plastic): set only by a solver with the
      !> plastic cap (cg); absent, no pixel is capped. Not in checkpoints.
      integer, allocatable :: step_plastic(:)
      real(dp), allocatable :: step_load(:), step_approach(:), step_seconds(:)
      !> Per step, the friction force of the shear model (nN; 0 without one).
      real(dp), allocatable :: step_friction(:)
      !> Requested loads, in the order given.
      type(load_state), allocatable :: states(:)
      !> Contact pixels (row, column, step joined) and their forces at the reported state.
      integer, allocatable :: contact_i(:), contact_j(:), contact_step(:)
      real(dp), allocatable :: contact_force(:)
      !> Load at which `contact_force` is reported.
      real(dp) :: reported_load = 0
      integer :: stop_reason = 0
      real(dp) :: wall_seconds = 0
      !> The memory the run was estimated to need at its largest (bytes: what the process
      !> held when the solver began and the solver's storage model; 0 where the solver has
      !> none), checked against the machine's before the solve.
      integer(i8) :: estimated_peak_bytes = 0
      !> The solver's own account (a type extending solver_diagnostics); read it with
      !> event_checks, legacy_checks and cg_work.
      class(solver_diagnostics), allocatable :: diagnostics
   end type contact_result

contains

   !> The fields that continue an event-path run (femcod_state_visitor): the history,
   !> the requested load states (reached or not), the counters. The timing and the
   !> final checks are not kept: they belong to the run that finishes.
   subroutine visit_result(self, visitor)
      type(contact_result), intent(inout) :: self
      class(state_visitor), intent(inout) :: visitor
      integer :: k, m
      call visitor%group("history")
      call visitor%integer_value("steps", self%nsteps)
      m = self%nsteps
      call grow_history(self, m)
      call visitor%integer_prefix("contacts", self%step_contacts, m)
      call visitor%integer_prefix("above_hardness", self%step_above_hardness, m)
      call visitor%real_prefix("load", self%step_load, m)
      call visitor%real_prefix("approach", self%step_approach, m)
      call visitor%real_prefix("seconds", self%step_seconds, m)
      call visitor%real_prefix("friction", self%step_friction, m)
      do k = 1, size(self%states)
         call visitor%group("states/"//int_str(k))
         associate(s => self%states(k))
            call visitor%logical_value("reached", s%reached)
            call visitor%real_value("load", s%load)
            call visitor%real_value("approach", s%approach)
            call visitor%integer_value("contacts", s%contacts)
            call visitor%real_value("max_pressure", s%max_pressure)
            call visitor%integer_value("n_above_hardness", s%n_above_hardness)
            call visitor%real_value("friction", s%friction)
            if (.not. allocated(s%i)) allocate(s%i(0), s%j(0), s%force(0))
            call visitor%integer_array("i", s%i)
            call visitor%integer_array("j", s%j)
            call visitor%real_array("force", s%force)
         end associate
      end do
   end subroutine visit_result

   !> The event path's counters that continue with its run (after visit_result's fields,
   !> in the checkpoint's group "counters"); the final checks belong to the run that
   !> finishes.
   subroutine visit_event_checks(self, visitor)
      type(event_path_diagnostics), intent(inout) :: self
      class(state_visitor), intent(inout) :: visitor
      call visitor%group("counters")
      call visitor%integer_value("missed_during_run", self%missed_during_run)
      call visitor%integer_value("releases", self%releases)
      call visitor%long_value("evaluations", self%evaluations)
      call visitor%integer_value("cache_hits", self%cache_hits)
      call visitor%integer_value("cache_misses", self%cache_misses)
      call visitor%integer_value("cache_refills", self%cache_refills)
      call visitor%integer_value("cache_columns", self%cache_columns)
      call visitor%integer_value("fft_steps", self%fft_steps)
   end subroutine visit_event_checks

   !> The event path's checks of a result (legacy's included); zeros for another solver.
   pure function event_checks(res) result(checks)
      type(contact_result), intent(in) :: res
      type(event_path_diagnostics) :: checks
      if (.not. allocated(res%diagnostics)) return
      select type (d => res%diagnostics)
      type is (event_path_diagnostics)
         checks = d
      type is (legacy_diagnostics)
         checks = d%event_path_diagnostics
      end select
   end function event_checks

   !> The legacy solver's account; its defaults (pivot loss 1, condition 0) for another.
   pure function legacy_checks(res) result(checks)
      type(contact_result), intent(in) :: res
      type(legacy_diagnostics) :: checks
      if (.not. allocated(res%diagnostics)) return
      select type (d => res%diagnostics)
      type is (legacy_diagnostics)
         checks = d
      end select
   end function legacy_checks

   !> The cg solver's work at state k; the defaults (0 iterations, no bound) for another
   !> solver or a state it did not reach.
   pure function cg_work(res, k) result(work)
      type(contact_result), intent(in) :: res
      integer, intent(in) :: k
      type(cg_state_diagnostics) :: work
      if (.not. allocated(res%diagnostics)) return
      select type (d => res%diagnostics)
      type is (cg_diagnostics)
         if (allocated(d%states)) then
            if (k >= 1 .and. k <= size(d%states)) work = d%states(k)
         end if
      end select
   end function cg_work

   !> The cg solver's iterations over all its states (0 for another solver).
   pure integer function cg_iterations_in_all(res) result(n)
      type(contact_result), intent(in) :: res
      integer :: k
      n = 0
      do k = 1, size(res%states)
         associate(work => cg_work(res, k))
            n = n + work%iterations
         end associate
      end do
   end function cg_iterations_in_all

   !> The cg solver's largest residual over its states (0 for another solver).
   pure real(dp) function largest_cg_residual(res) result(r)
      type(contact_result), intent(in) :: res
      integer :: k
      r = 0
      do k = 1, size(res%states)
         associate(work => cg_work(res, k))
            r = max(r, work%residual)
         end associate
      end do
   end function largest_cg_residual

   !> Room for at least `m` history rows: 64 at first, doubled as needed (amortised O(1)
   !> per appended row).
   pure subroutine grow_history(res, m)
      type(contact_result), intent(inout) :: res
      integer, intent(in) :: m
      integer :: cap
      if (.not. allocated(res%step_contacts)) then
         allocate(res%step_contacts(64), res%step_above_hardness(64), res%step_load(64), res%step_approach(64), &
            res%step_seconds(64), res%step_friction(64))
      end if
      do while (size(res%step_contacts) < m)
         cap = 2*size(res%step_contacts)
         call grow(res%step_contacts, cap)
         call grow(res%step_above_hardness, cap)
         call grow(res%step_load, cap)
         call grow(res%step_approach, cap)
         call grow(res%step_seconds, cap)
         call grow(res%step_friction, cap)
      end do
   end subroutine grow_history

   !> Append one history row: contacts carrying load, how many of them press harder
   !> than the hardness, total load (nN), approach (nm), seconds the step took, and the
   !> friction force of the shear model (nN; 0 without one).
   pure subroutine append_step(res, contacts, above_hardness, load, approach, seconds, friction)
      type(contact_result), intent(inout) :: res
      integer, intent(in) :: contacts, above_hardness
      real(dp), intent(in) :: load, approach, seconds, friction
      call grow_history(res, res%nsteps + 1)
      res%nsteps = res%nsteps + 1
      res%step_contacts(res%nsteps) = contacts
      res%step_above_hardness(res%nsteps) = above_hardness
      res%step_load(res%nsteps) = load
      res%step_approach(res%nsteps) = approach
      res%step_seconds(res%nsteps) = seconds
      res%step_friction(res%nsteps) = friction
   end subroutine append_step

   !> Record the states at the requested loads that fall inside the current step, which
   !> starts at `total` and ends `lam` later (`bounded` false: the step never ends).
   !> Within a step the response is linear, so the interpolation is exact. The contacts
   !> (ic, jc) and their forces are kept for the maps; at the largest requested load
   !> also for the contacts file.
   pure subroutine record_load_states(res, lam, bounded, total, approach, delta, ftot, funit, pixel, hardness, ic, jc, &
      shear)
      type(contact_result), intent(inout) :: res
      real(dp), intent(in) :: lam, total, approach, delta, ftot(:), funit(:), pixel, hardness
      type(shear_model), intent(in) :: shear
      integer, intent(in) :: ic(:), jc(:)
      logical, intent(in) :: bounded
      integer :: s
      real(dp) :: dl
      do s = 1, size(res%states)
         if (res%states(s)%reached) cycle
         if (bounded .and. res%states(s)%load > total + lam) cycle
         dl = max(res%states(s)%load - total, 0.0_dp)
         res%states(s)%approach = approach + dl*delta
         call fill_state(res%states(s), ftot + dl*funit, pixel, hardness, ic, jc, shear)
         if (res%states(s)%load == maxval(res%states%load)) then
            res%contact_force = res%states(s)%force
            res%reported_load = res%states(s)%load
         end if
      end do
   end subroutine record_load_states

   !> As record_load_states for requested approaches (displacement control): an unreached
   !> state's approach is its target D; within the step the approach is approach + l delta,
   !> so D is reached at l = (D - approach)/delta, where the load is total + l.
   pure subroutine record_approach_states(res, lam, bounded, total, approach, delta, ftot, funit, pixel, hardness, &
      ic, jc, shear)
      type(contact_result), intent(inout) :: res
      real(dp), intent(in) :: lam, total, approach, delta, ftot(:), funit(:), pixel, hardness
      type(shear_model), intent(in) :: shear
      integer, intent(in) :: ic(:), jc(:)
      logical, intent(in) :: bounded
      integer :: s
      real(dp) :: dl
      if (.not. delta > 0) return
      do s = 1, size(res%states)
         if (res%states(s)%reached) cycle
         dl = max(res%states(s)%approach - approach, 0.0_dp)/delta
         if (bounded .and. dl > lam) cycle
         res%states(s)%load = total + dl
         call fill_state(res%states(s), ftot + dl*funit, pixel, hardness, ic, jc, shear)
         if (res%states(s)%approach == maxval(res%states%approach)) then
            res%contact_force = res%states(s)%force
            res%reported_load = res%states(s)%load
         end if
      end do
   end subroutine record_approach_states

   !> A state reached with the contact forces f (nN) at pixels (ic, jc): its contacts,
   !> largest pressure and count above the hardness (GPa), pixel d (nm), and the friction
   !> force of the shear model (0 without one).
   pure subroutine fill_state(state, f, pixel, hardness, ic, jc, shear)
      type(load_state), intent(inout) :: state
      real(dp), intent(in) :: f(:), pixel, hardness
      integer, intent(in) :: ic(:), jc(:)
      type(shear_model), intent(in) :: shear
      state%contacts = size(f)
      state%max_pressure = 0
      if (size(f) > 0) state%max_pressure = maxval(f)/pixel**2
      state%n_above_hardness = count(f/pixel**2 > hardness)
      state%friction = friction_force(shear, f, pixel)
      state%reached = .true.
      state%i = ic
      state%j = jc
      state%force = f
   end subroutine fill_state

   !> Store the contact pixels; the forces at the end when no requested load set them.
   pure subroutine finish_contacts(res, ic, jc, cstep, ftot, total)
      type(contact_result), intent(inout) :: res
      integer, intent(in) :: ic(:), jc(:), cstep(:)
      real(dp), intent(in) :: ftot(:), total
      if (.not. allocated(res%contact_force)) then
         res%contact_force = ftot
         res%reported_load = total
      end if
      res%contact_i = ic
      res%contact_j = jc
      res%contact_step = cstep
   end subroutine finish_contacts

   pure function stop_reason_text(reason) result(text)
      integer, intent(in) :: reason
      character(len=:), allocatable :: text
      select case (reason)
      case (STOP_MAXCONT)
         text = "maximum number of contacts reached"
      case (STOP_LOADS)
         text = "all requested loads reached"
      case (STOP_NO_CONTACT)
         text = "no further pixel can come into contact"
      case (STOP_INTERRUPTED)
         text = "interrupted by a stop signal: a partial run"
      case default
         text = "not run"
      end select
   end function stop_reason_text
   !> The state's contacts from a map: the pixels (row, column) where `in_contact` holds,
   !> row by row, with their forces (nN) from `force`; and their count. The maps are read
   !> column by column, as they are stored: each row's contacts are counted first, so
   !> that every contact goes straight to its place in row order.
   pure subroutine gather_contacts(state, in_contact, force)
      type(load_state), intent(inout) :: state
      logical, intent(in) :: in_contact(:, :)
      real(dp), intent(in) :: force(:, :)
      integer, allocatable :: next(:)
      integer :: i, j, nc
      allocate(next(size(in_contact, 1)))
      next = 0
      do j = 1, size(in_contact, 2)
         do i = 1, size(in_contact, 1)
            if (in_contact(i, j)) next(i) = next(i) + 1
         end do
      end do
      ! next(i): the place of row i's next contact.
      nc = 0
      do i = 1, size(next)
         nc = nc + next(i)
         next(i) = nc - next(i) + 1
      end do
      state%contacts = nc
      allocate(state%i(nc), state%j(nc), state%force(nc))
      do j = 1, size(in_contact, 2)
         do i = 1, size(in_contact, 1)
            if (in_contact(i, j)) then
               state%i(next(i)) = i
               state%j(next(i)) = j
               state%force(next(i)) = force(i, j)
               next(i) = next(i) + 1
            end if
         end do
      end do
   end subroutine gather_contacts
end module femcod_contact_result
