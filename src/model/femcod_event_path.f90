!> The load path of the two event solvers (legacy/femcod_legacy and
!> solvers/femcod_incremental): contact grows event by event, each step linear in the
!> load. What they share is kept here: the tied first contacts, the end of a step (the
!> requested loads inside it, the advance, the history row) and when to stop.
!>
!> Within a step the forces grow as ftot + lam funit and the approach as
!> approach + lam delta, for lam from 0 to the step's load increment; a state at a
!> requested load inside the step is therefore exact.
module femcod_event_path
   use femcod_kinds, only: dp
   use femcod_clock, only: wall_clock
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: contact_options, run_shear_model
   use femcod_shear_model, only: shear_model, friction_force
   use femcod_contact_result, only: contact_result, append_step, record_load_states, record_approach_states, &
      STOP_LOADS, STOP_NO_CONTACT
   implicit none
   private
   public :: load_path, first_touch_limit, NO_EVENT

   !> The load increment that stands for "nothing closes and nothing is released".
   real(dp), parameter :: NO_EVENT = huge(1.0_dp)

   !> Where a path is: total load (nN), approach (nm), and what ends it.
   type :: load_path
      real(dp) :: total = 0, approach = 0
      !> The largest requested load (nN), and whether any was requested; the same for
      !> requested approaches (nm, displacement control).
      real(dp) :: max_load = -huge(1.0_dp), max_approach = -huge(1.0_dp)
      logical :: has_loads = .false., has_approaches = .false.
      !> The contacts the path may hold: MAXCONT, or fewer by --max-contacts.
      integer :: max_contacts = 0
      !> Pixel size (nm) and hardness (GPa), for the pressures of the history and states.
      real(dp) :: pixel = 0, hardness = 0
      !> The shear model, for the friction force of each step and state (inactive: none).
      type(shear_model) :: shear
   contains
      procedure :: start => start_path
      procedure :: advance
      procedure :: close_step
      procedure :: room_for
   end type load_path

contains

   !> Set the path up at zero load and the result's requested load states.
   subroutine start_path(path, problem, options, res)
      class(load_path), intent(out) :: path
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(inout) :: res
      real(dp), allocatable :: loads(:)
      ! --max-contacts replaces the deck's MAXCONT (either way, at most every pixel).
      path%max_contacts = problem%maxcont
      if (options%max_contacts > 0) path%max_contacts = options%max_contacts
      path%max_contacts = min(path%max_contacts, problem%np**2)
      if (allocated(options%loads)) then
         loads = options%loads
      else
         allocate(loads(0))
      end if
      path%has_loads = size(loads) > 0
      if (path%has_loads) path%max_load = maxval(loads)
      path%pixel = problem%pixel
      path%hardness = options%hardness
      path%shear = run_shear_model(options)
      path%has_approaches = .false.
      if (allocated(options%approaches)) path%has_approaches = size(options%approaches) > 0
      if (path%has_approaches) then
         ! Displacement control: the targets wait in the states' approach; those at or
         ! below first touch are reached at once, with no load and no contact.
         path%max_approach = maxval(options%approaches)
         allocate(res%states(size(options%approaches)))
         res%states%approach = options%approaches
         res%states%load = 0
         where (options%approaches <= 0) res%states%reached = .true.
         call record_untouched(res)
         return
      end if
      allocate(res%states(size(loads)))
      res%states%load = loads
   end subroutine start_path

   !> The states reached before any contact: no force, no contact.
   pure subroutine record_untouched(res)
      type(contact_result), intent(inout) :: res
      integer :: s
      do s = 1, size(res%states)
         if (.not. res%states(s)%reached) cycle
         res%states(s)%contacts = 0
         res%states(s)%max_pressure = 0
         allocate(res%states(s)%i(0), res%states(s)%j(0), res%states(s)%force(0))
      end do
   end subroutine record_untouched

   !> The gap below which a pixel touches together with the first one (gap `first`): the
   !> tie tolerance of the gaps' range, since the load scale is still zero.
   pure real(dp) function first_touch_limit(g0, first, tie_tolerance)
      real(dp), intent(in) :: g0(:), first, tie_tolerance
      first_touch_limit = first + tie_tolerance*(maxval(g0) - first)
   end function first_touch_limit

   !> Move along the step by the load increment `lam` (nN): total load, approach (rate
   !> `delta`, nm/nN) and the forces (rates `funit`).
   pure subroutine advance(path, lam, delta, ftot, funit)
      class(load_path), intent(inout) :: path
      real(dp), intent(in) :: lam, delta, funit(:)
      real(dp), intent(inout) :: ftot(:)
      path%total = path%total + lam
      path%approach = path%approach + lam*delta
      ftot = ftot + lam*funit
   end subroutine advance

   !> End the step that began at wall time `t0` (s) with the load increment `lam` to the
   !> next event (NO_EVENT: none; the path is linear for ever): record the requested
   !> loads inside it, advance (to the largest requested load when no event comes) and
   !> append the history row. Returns the stop reason, 0 to go on.
   integer function close_step(path, res, lam, delta, ftot, funit, ic, jc, t0) result(reason)
      class(load_path), intent(inout) :: path
      type(contact_result), intent(inout) :: res
      real(dp), intent(in) :: lam, delta, funit(:), t0
      real(dp), intent(inout) :: ftot(:)
      integer, intent(in) :: ic(:), jc(:)
      real(dp) :: t1
      reason = 0
      if (path%has_approaches) then
         ! Displacement control: the states where the approach crosses a target.
         if (lam >= NO_EVENT) then
            call record_approach_states(res, NO_EVENT, .false., path%total, path%approach, delta, ftot, funit, &
               path%pixel, path%hardness, ic, jc, path%shear)
            reason = STOP_NO_CONTACT
            if (path%max_approach > path%approach .and. delta > 0) &
               call path%advance((path%max_approach - path%approach)/delta, delta, ftot, funit)
         else
            call record_approach_states(res, lam, .true., path%total, path%approach, delta, ftot, funit, &
               path%pixel, path%hardness, ic, jc, path%shear)
            call path%advance(lam, delta, ftot, funit)
            if (path%max_approach <= path%approach) reason = STOP_LOADS
         end if
      else if (lam >= NO_EVENT) then
         call record_load_states(res, NO_EVENT, .false., path%total, path%approach, delta, ftot, funit, &
            path%pixel, path%hardness, ic, jc, path%shear)
         reason = STOP_NO_CONTACT
         if (path%has_loads) then
            if (path%max_load > path%total) call path%advance(path%max_load - path%total, delta, ftot, funit)
         end if
      else
         call record_load_states(res, lam, .true., path%total, path%approach, delta, ftot, funit, &
            path%pixel, path%hardness, ic, jc, path%shear)
         call path%advance(lam, delta, ftot, funit)
         if (path%has_loads) then
            if (path%max_load <= path%total) reason = STOP_LOADS
         end if
      end if
      call wall_clock(t1)
      call append_step(res, size(ftot), count(ftot/path%pixel**2 > path%hardness), path%total, path%approach, &
         t1 - t0, friction_force(path%shear, ftot, path%pixel))
   end function close_step

   !> Whether `joining` more contacts fit beside the `n` there are.
   pure logical function room_for(path, n, joining)
      class(load_path), intent(in) :: path
      integer, intent(in) :: n, joining
      room_for = n + joining <= path%max_contacts
   end function room_for
end module femcod_event_path
