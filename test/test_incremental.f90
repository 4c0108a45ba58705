!> The event-exact incremental solver against the legacy program (same events) and
!> against an independent fixed-load active-set solution of the contact problem.
module test_incremental
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings
   use femcod_solver, only: solve_contact
   use femcod_generate, only: VERIFICATION_DECKS
   use femcod_scene, only: initial_gaps
   use femcod_love, only: offset_table, surface_compliance
   use femcod_condensed, only: solve_active_set, gap_at
   use femcod_spring, only: spring_stiffness
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   use omp_lib, only: omp_set_num_threads, omp_get_max_threads
   implicit none
   private
   public :: collect_incremental

contains

   subroutine collect_incremental(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("same events as legacy on every input/ deck", test_same_events), &
         new_unittest("rigid springs: equals a fixed-load active-set solution", test_active_set), &
         new_unittest("Table 4.1 and 4.2 values, with no missed contact", test_tables), &
         new_unittest("a deck whose MAXCONT is NP^2 runs (the factor grows)", test_growth), &
         new_unittest("OpenMP: 1 and 2 threads give the same results", test_threads), &
         new_unittest("event search: full-field FFT and gap bound find the same events", test_event_search) &
         ]
   end subroutine collect_incremental

   !> Merge steps with no load increment (the legacy candidate list splits a tie that
   !> is larger than the list over several steps with no load increment; the incremental
   !> solver takes the whole tie at once): keep the first row of each run of equal loads,
   !> the contacts that carried the load up to that event.
   subroutine events(res, loads, counts, m)
      type(contact_result), intent(in) :: res
      real(dp), intent(out) :: loads(:)
      integer, intent(out) :: counts(:), m
      integer :: k
      m = 0
      do k = 1, res%nsteps
         if (m > 0) then
            if (abs(res%step_load(k) - loads(m)) <= 1.0e-12_dp*max(abs(loads(m)), 1.0e-300_dp)) cycle
         end if
         m = m + 1
         loads(m) = res%step_load(k)
         counts(m) = res%step_contacts(k)
      end do
   end subroutine events

   subroutine test_same_events(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc, leg
      type(status_type) :: status
      real(dp), allocatable :: li(:), ll(:)
      integer, allocatable :: ci(:), cl(:)
      integer :: d, mi, ml, k
      real(dp) :: worst
      do d = 1, size(VERIFICATION_DECKS)
         ! The 0.5 nm sphere to 18000 nN is in the legacy suite; here it runs to 3000 nN.
         call read_deck("input/"//trim(VERIFICATION_DECKS(d))//".deck", deck, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         options%loads = [1.0_dp]
         if (index(VERIFICATION_DECKS(d), "sphere") > 0) options%loads = [3000.0_dp]
         if (index(VERIFICATION_DECKS(d), "rough") > 0) deallocate(options%loads)
         options%solver = "incremental"
         call solve_contact(deck, options, inc, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         options%solver = "legacy"
         call solve_contact(deck, options, leg, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         allocate(li(inc%nsteps), ci(inc%nsteps), ll(leg%nsteps), cl(leg%nsteps))
         call events(inc, li, ci, mi)
         call events(leg, ll, cl, ml)
         call check(error, mi, ml, trim(VERIFICATION_DECKS(d))//": number of events")
         if (allocated(error)) return
         call check(error, all(ci(1:mi) == cl(1:ml)), trim(VERIFICATION_DECKS(d))//": contacts at every event")
         if (allocated(error)) return
         worst = 0
         do k = 1, mi
            if (ll(k) > 0) worst = max(worst, abs(li(k) - ll(k))/ll(k))
         end do
         ! The issue asks 1e-9; legacy with its refinement step agrees to about 1e-10.
         call check(error, worst < 1.0e-9_dp, trim(VERIFICATION_DECKS(d))//": loads within 1e-9, worst "// &
            to_string(worst))
         if (allocated(error)) return
         if (allocated(options%loads)) then
            call check(error, inc%states(1)%approach, leg%states(1)%approach, rel=.true., thr=1.0e-9_dp, &
               message=trim(VERIFICATION_DECKS(d))//": approach at the requested load")
            if (allocated(error)) return
         end if
         deallocate(li, ci, ll, cl)
      end do
   end subroutine test_same_events

   !> Independent reference: Kalker-style fixed-load active-set iteration on the dense
   !> condensed system (LAPACK dsysv): start from the pixels the rigid approach would
   !> touch, drop the most tensile contact or add the most penetrating pixel until
   !> neither exists. A different algorithm from the event stepping.
   subroutine test_active_set(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc
      type(status_type) :: status
      real(dp), allocatable :: g0(:), table(:, :), f(:)
      integer, allocatable :: ic(:), jc(:), pix(:)
      logical, allocatable :: active(:)
      real(dp) :: c, s, a, gap, worst_gap, load
      integer :: np, p, n, it, k, worst_pix, idx, l
      real(dp), parameter :: loads(3) = [300.0_dp, 2000.0_dp, 8000.0_dp]
      call read_deck("input/rough_selfaffine_32.deck", deck, status)
      ! Rigid springs: contact modulus so large that 3/k is below round-off of c.
      deck%young(3) = 1.0e25_dp
      np = deck%np
      options%loads = loads
      options%solver = "incremental"
      call solve_contact(deck, options, inc, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      g0 = initial_gaps(deck%lower, deck%upper)
      allocate(table(0:np - 1, 0:np - 1))
      table = offset_table(np)
      c = surface_compliance(deck%young(1), deck%poisson(1), deck%pixel) + &
         surface_compliance(deck%young(2), deck%poisson(2), deck%pixel)
      s = 3/spring_stiffness(deck%young(3), deck%poisson(3), deck%pixel, deck%pixel)
      do l = 1, size(loads)
         load = loads(l)
         allocate(active(np*np))
         active = g0 <= minval(g0) + 1.0e-9_dp
         do it = 1, 10*np*np
            n = count(active)
            pix = pack([(p, p = 1, np*np)], active)
            ic = (pix - 1)/np + 1
            jc = pix - (ic - 1)*np
            if (allocated(f)) deallocate(f)
            allocate(f(n))
            call solve_active_set(ic, jc, g0(pix), c, s, table, load, f, a, status)
            if (minval(f) < 0) then
               idx = minloc(f, 1)
               active(pix(idx)) = .false.
               cycle
            end if
            worst_gap = 0
            worst_pix = 0
            do p = 1, np*np
               if (active(p)) cycle
               gap = gap_at(g0(p), a, c, table, (p - 1)/np + 1, p - ((p - 1)/np)*np, ic, jc, f)
               if (gap < worst_gap) then
                  worst_gap = gap
                  worst_pix = p
               end if
            end do
            if (worst_pix == 0) exit
            active(worst_pix) = .true.
         end do
         call check(error, inc%states(l)%contacts, n, "contacts at "//to_string(nint(load))//" nN")
         if (allocated(error)) return
         call check(error, inc%states(l)%approach, a, rel=.true., thr=1.0e-10_dp, &
            message="approach at "//to_string(nint(load))//" nN")
         if (allocated(error)) return
         deallocate(active)
      end do
      ! Forces at the largest load, pixel by pixel.
      do k = 1, size(inc%contact_i)
         idx = findloc(pix, (inc%contact_i(k) - 1)*np + inc%contact_j(k), 1)
         call check(error, idx > 0, "same contact set")
         if (allocated(error)) return
         call check(error, inc%contact_force(k), f(idx), rel=.true., thr=1.0e-8_dp, message="force")
         if (allocated(error)) return
      end do
   end subroutine test_active_set

   subroutine test_tables(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc
      type(status_type) :: status
      character(len=*), parameter :: decks(2) = [character(len=16) :: "circle_punch_d9", "square_punch_n27"]
      ! Thesis Tables 4.1 and 4.2, finest meshes: 0.911e-3 and 0.412e-3 nm at 1 nN.
      real(dp), parameter :: thesis(2) = [0.911e-3_dp, 0.412e-3_dp]
      integer :: k
      do k = 1, 2
         call read_deck("input/"//trim(decks(k))//".deck", deck, status)
         options%loads = [1.0_dp]
         options%solver = "incremental"
         call solve_contact(deck, options, inc, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         call check(error, inc%states(1)%approach, thesis(k), rel=.true., thr=5.0e-3_dp, message=trim(decks(k)))
         if (allocated(error)) return
         call check(error, inc%missed_final_check, 0, "no pixel penetrates at the end")
         if (allocated(error)) return
         call check(error, inc%final_check_difference < 1.0e-10_dp, "drift against a fresh solve: "// &
            to_string(inc%final_check_difference))
         if (allocated(error)) return
      end do
   end subroutine test_tables

   subroutine test_growth(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc
      type(status_type) :: status
      call read_deck("input/rough_selfaffine_32.deck", deck, status)
      deck%maxcont = deck%np**2
      options%max_contacts = 600
      allocate(options%loads(0))
      options%solver = "incremental"
      call solve_contact(deck, options, inc, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call check(error, size(inc%contact_i) >= 590 .and. inc%missed_final_check == 0 .and. &
         inc%final_check_difference < 1.0e-10_dp, "600 of 1024 pixels in contact, none missed, no drift: "// &
         to_string(size(inc%contact_i))//" "//to_string(inc%final_check_difference))
      if (allocated(error)) return
      call check(error, all(inc%contact_force >= 0), "no tensile force")
   end subroutine test_growth

   subroutine test_threads(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: one, two
      type(status_type) :: status
      real(dp), allocatable :: t1(:, :), t2(:, :)
      integer :: saved, k
      saved = omp_get_max_threads()
      call omp_set_num_threads(1)
      t1 = offset_table(64)
      call read_deck("input/rough_selfaffine_32.deck", deck, status)
      allocate(options%loads(0))
      options%solver = "incremental"
      call solve_contact(deck, options, one, status)
      call omp_set_num_threads(2)
      t2 = offset_table(64)
      options%solver = "incremental"
      call solve_contact(deck, options, two, status)
      call omp_set_num_threads(saved)
      call check(error, all(t1 == t2), "offset table bit for bit")
      if (allocated(error)) return
      call check(error, one%nsteps == two%nsteps .and. all(one%step_contacts(1:one%nsteps) == &
         two%step_contacts(1:two%nsteps)), "same events")
      if (allocated(error)) return
      do k = 1, one%nsteps
         call check(error, two%step_load(k), one%step_load(k), rel=.true., thr=1.0e-12_dp)
         if (allocated(error)) return
      end do
   end subroutine test_threads

   !> Two independent event searches: the heap of gap bounds with exact evaluations, and
   !> gaps and rates of every pixel from two FFT convolutions. The same events on every
   !> input/ deck (contacts equal, loads to 1e-12); auto reports its choice.
   subroutine test_event_search(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: a, b
      type(status_type) :: status
      integer :: d, n
      do d = 1, size(VERIFICATION_DECKS)
         if (index(VERIFICATION_DECKS(d), "d05") > 0 .or. index(VERIFICATION_DECKS(d), "d9") > 0) cycle
         call read_deck("input/"//trim(VERIFICATION_DECKS(d))//".deck", deck, status)
         options%loads = [real(dp) ::]
         if (index(VERIFICATION_DECKS(d), "sphere") > 0) options%loads = [3000.0_dp]
         options%event_search = "bound"
         options%solver = "incremental"
         call solve_contact(deck, options, a, status)
         options%event_search = "fft"
         options%solver = "incremental"
         call solve_contact(deck, options, b, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         n = a%nsteps
         call check(error, b%nsteps == n .and. b%fft_steps == n .and. a%fft_steps == 0, &
            trim(VERIFICATION_DECKS(d))//": steps and search counts")
         if (allocated(error)) return
         call check(error, all(a%step_contacts(1:n) == b%step_contacts(1:n)), trim(VERIFICATION_DECKS(d))// &
            ": contacts at every step")
         if (allocated(error)) return
         call check(error, maxval(abs(a%step_load(1:n) - b%step_load(1:n))) <= 1.0e-12_dp*maxval(a%step_load(1:n)), &
            trim(VERIFICATION_DECKS(d))//": loads")
         if (allocated(error)) return
      end do
      options%event_search = "auto"
      options%solver = "incremental"
      call solve_contact(deck, options, b, status)
      call check(error, b%fft_steps >= 0 .and. b%fft_steps <= b%nsteps, "auto reports its choice")
   end subroutine test_event_search
end module test_incremental
