!> What a contact solver returns: the step history, the states at requested loads,
!> the contact pixels with their forces, and what was checked.
module femcod_contact_result
   use femcod_kinds, only: dp, i8
   implicit none
   private
   public :: contact_result, load_state, contact_options, append_step, progress_interface
   public :: STOP_MAXCONT, STOP_LOADS, STOP_NO_CONTACT, stop_reason_text, record_load_states, finish_contacts
   public :: solver_state, checkpoint_interface

   integer, parameter :: STOP_MAXCONT = 1, STOP_LOADS = 2, STOP_NO_CONTACT = 3

   !> What the user asked of a run.
   type :: contact_options
      !> Stop after this many contacts (0: the deck's MAXCONT).
      integer :: max_contacts = 0
      !> Requested total loads (nN); empty: run to MAXCONT.
      real(dp), allocatable :: loads(:)
      !> Hardness (GPa) for the count of pixels above it (thesis polysilicon: 11 GPa).
      real(dp) :: hardness = 11
      !> Candidates whose closing load is within this fraction of the total load of the
      !> smallest one join in the same step (ties).
      real(dp) :: tie_tolerance = 1.0e-9_dp
      !> Check every pixel for penetration at the end, and correct (Appendix B).
      logical :: final_check = .true.
      !> Event search of the incremental solver: "auto" (the cheaper of the two, from
      !> measured costs), "bound" (gap bound and exact evaluations) or "fft" (full field).
      character(len=5) :: event_search = "auto"
      !> Hand the solver state to the checkpoint procedure every this many seconds of
      !> wall time (0: after every step; negative: never).
      real(dp) :: checkpoint_interval = -1
   end type contact_options

   !> The contact state at one requested load.
   type :: load_state
      real(dp) :: load = 0, approach = 0
      integer :: contacts = 0
      real(dp) :: max_pressure = 0
      integer :: n_above_hardness = 0
      logical :: reached = .false.
      !> Fixed-load solver only: iterations, relative complementarity residual, deepest
      !> penetration (nm), largest |gap| on contact (nm), relative load error.
      integer :: iterations = 0
      real(dp) :: residual = 0, penetration = 0, contact_gap = 0, load_error = 0
      !> The contact pixels (row, column) and their forces (nN) at this load.
      integer, allocatable :: i(:), j(:)
      real(dp), allocatable :: force(:)
   end type load_state

   !> Results of a run. Units: nN, nm, GPa.
   type :: contact_result
      integer :: nsteps = 0
      !> Per step: contacts carrying load, total load and approach at the end of the step,
      !> and the contacts whose pressure exceeds the hardness there (thesis Fig. 4.21).
      integer, allocatable :: step_contacts(:), step_above_hardness(:)
      real(dp), allocatable :: step_load(:), step_approach(:), step_seconds(:)
      !> Requested loads, in the order given.
      type(load_state), allocatable :: states(:)
      !> Contact pixels (row, column, step joined) and their forces at the reported state.
      integer, allocatable :: contact_i(:), contact_j(:), contact_step(:)
      real(dp), allocatable :: contact_force(:)
      !> Load at which `contact_force` is reported.
      real(dp) :: reported_load = 0
      integer :: stop_reason = 0
      !> Contacts found late by the candidate search (joined with a penetration),
      !> and by the final check over all pixels.
      integer :: missed_during_run = 0, missed_final_check = 0
      !> Contacts released (force reached zero) during the run.
      integer :: releases = 0
      !> Exact pixel evaluations made by the candidate search (incremental solver).
      integer(i8) :: evaluations = 0
      !> Incremental solver: contacts whose bordering columns came from the candidate
      !> cache, contacts that needed their own triangular solves, and cache refills.
      integer :: cache_hits = 0, cache_misses = 0, cache_refills = 0, cache_columns = 0
      !> Incremental solver: steps whose event search used the full-field FFT.
      integer :: fft_steps = 0
      !> Largest relative difference between the accumulated state and an exact
      !> active-set solve at the end (a consistency check of the step accumulation).
      real(dp) :: final_check_difference = 0
      !> Deepest penetration of any pixel not in contact at the end (nm, >= 0), from the
      !> full-field check.
      real(dp) :: max_penetration = 0
      !> Legacy solver: the largest TRFACT pivot loss of the run (about log10 of it digits
      !> lost to cancellation; 1 for the incremental solver, which has no springs in its
      !> matrix).
      real(dp) :: pivot_loss = 1
      !> Legacy solver: the largest 1-norm condition estimate of its skyline system
      !> (TRFACT + LAPACK dlacn2); 0 for the incremental solver.
      real(dp) :: condition = 0
      real(dp) :: wall_seconds = 0
   end type contact_result

   !> Everything the incremental solver needs to continue a run exactly where it was,
   !> bit for bit: the contacts, the Cholesky factor and the vectors derived from it,
   !> the candidate cache and the event heap, the accumulated load, approach and forces.
   type :: solver_state
      integer :: step = 0, n = 0
      real(dp) :: total = 0, approach = 0, phi = 0
      !> The current contacts: pixel (row-wise number), step joined, force (nN).
      integer, allocatable :: pix(:), cstep(:)
      real(dp), allocatable :: ftot(:)
      !> Leading dimension of the factor's storage and the factor's upper triangle,
      !> packed column by column; y = U^-T 1 and x = M^-1 1.
      integer :: ld = 0
      real(dp), allocatable :: factor(:), y(:), x(:)
      !> Candidate cache: pixel per slot (0: empty), columns l and w (n x slots), the
      !> predicted closing loads, contacts joined since the last refill.
      integer, allocatable :: cache_pixel(:)
      real(dp), allocatable :: cache_l(:, :), cache_w(:, :), predicted(:)
      integer :: since_refill = 0
      !> Exact evaluations of the last bound search (the event-search choice).
      integer :: last_neval = 0
      !> The event heap: keys and items in heap order.
      real(dp), allocatable :: heap_key(:)
      integer, allocatable :: heap_item(:)
      !> The results so far (history, states reached, counters).
      type(contact_result) :: res
   end type solver_state

   abstract interface
      !> Called by a solver after every step, so that a program can report progress
      !> (the solver itself does no I/O): step, contacts, total load (nN), elapsed (s).
      subroutine progress_interface(step, contacts, load, elapsed)
         import :: dp
         integer, intent(in) :: step, contacts
         real(dp), intent(in) :: load, elapsed
      end subroutine progress_interface
      !> Called by a solver every `checkpoint_interval` seconds with its complete state
      !> at the end of a step; the program stores it (the solver does no I/O).
      subroutine checkpoint_interface(state)
         import :: solver_state
         type(solver_state), intent(in) :: state
      end subroutine checkpoint_interface
   end interface

contains

   !> Append one history row: contacts carrying load, how many of them press harder
   !> than the hardness, total load (nN), approach (nm), seconds the step took.
   pure subroutine append_step(res, contacts, above_hardness, load, approach, seconds)
      type(contact_result), intent(inout) :: res
      integer, intent(in) :: contacts, above_hardness
      real(dp), intent(in) :: load, approach, seconds
      integer, allocatable :: itmp(:)
      real(dp), allocatable :: rtmp(:)
      integer :: cap
      if (.not. allocated(res%step_contacts)) then
         allocate(res%step_contacts(64), res%step_above_hardness(64), res%step_load(64), res%step_approach(64), &
            res%step_seconds(64))
      end if
      cap = size(res%step_contacts)
      if (res%nsteps == cap) then
         allocate(itmp(2*cap))
         itmp(1:cap) = res%step_contacts
         call move_alloc(itmp, res%step_contacts)
         allocate(itmp(2*cap))
         itmp(1:cap) = res%step_above_hardness
         call move_alloc(itmp, res%step_above_hardness)
         allocate(rtmp(2*cap))
         rtmp(1:cap) = res%step_load
         call move_alloc(rtmp, res%step_load)
         allocate(rtmp(2*cap))
         rtmp(1:cap) = res%step_approach
         call move_alloc(rtmp, res%step_approach)
         allocate(rtmp(2*cap))
         rtmp(1:cap) = res%step_seconds
         call move_alloc(rtmp, res%step_seconds)
      end if
      res%nsteps = res%nsteps + 1
      res%step_contacts(res%nsteps) = contacts
      res%step_above_hardness(res%nsteps) = above_hardness
      res%step_load(res%nsteps) = load
      res%step_approach(res%nsteps) = approach
      res%step_seconds(res%nsteps) = seconds
   end subroutine append_step

   !> Record the states at the requested loads that fall inside the current step, which
   !> starts at `total` and ends `lam` later (`bounded` false: the step never ends).
   !> Within a step the response is linear, so the interpolation is exact. The contacts
   !> (ic, jc) and their forces are kept for the maps; at the largest requested load
   !> also for the contacts file.
   pure subroutine record_load_states(res, lam, bounded, total, approach, delta, ftot, funit, pixel, hardness, ic, jc)
      type(contact_result), intent(inout) :: res
      real(dp), intent(in) :: lam, total, approach, delta, ftot(:), funit(:), pixel, hardness
      integer, intent(in) :: ic(:), jc(:)
      logical, intent(in) :: bounded
      integer :: s
      real(dp) :: dl
      real(dp), allocatable :: f(:)
      do s = 1, size(res%states)
         if (res%states(s)%reached) cycle
         if (bounded .and. res%states(s)%load > total + lam) cycle
         dl = max(res%states(s)%load - total, 0.0_dp)
         f = ftot + dl*funit
         res%states(s)%approach = approach + dl*delta
         res%states(s)%contacts = size(ftot)
         res%states(s)%max_pressure = maxval(f)/pixel**2
         res%states(s)%n_above_hardness = count(f/pixel**2 > hardness)
         res%states(s)%reached = .true.
         res%states(s)%i = ic
         res%states(s)%j = jc
         res%states(s)%force = f
         if (res%states(s)%load == maxval(res%states%load)) then
            res%contact_force = f
            res%reported_load = res%states(s)%load
         end if
      end do
   end subroutine record_load_states

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
      case default
         text = "not run"
      end select
   end function stop_reason_text
end module femcod_contact_result
