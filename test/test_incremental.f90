!> The event-exact incremental solver against the legacy program (same events) and
!> against an independent fixed-load active-set solution of the contact problem.
module test_incremental
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result
   use test_support, only: fft_steps_of
   use femcod_solver_options, only: contact_options, &
      SOLVER_INCREMENTAL, SOLVER_LEGACY, SOLVER_CG
   use femcod_solver, only: solve_contact
   use femcod_generate, only: VERIFICATION_DECKS, scene_spec, build_problem
   use femcod_love, only: offset_table
   use femcod_event_search, only: fft_search_pays
   use femcod_thesis, only: TABLE_4_1_APPROACH, TABLE_4_2_APPROACH
   use oracles, only: love_table, exact_state, gaps_at_state, reference_gaps, event_path
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   use omp_lib, only: omp_set_num_threads, omp_get_max_threads
   implicit none
   private
   public :: collect_incremental, events

contains

   subroutine collect_incremental(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("same events as legacy on every input/ deck", test_same_events), &
         new_unittest("the events of a brute-force dense event path (oracle), spheres and the rough deck", &
            test_oracle_events), &
         new_unittest("rigid springs: equals a fixed-load active-set solution", test_active_set), &
         new_unittest("Tables 4.1, 4.2; the state against an exact solve and every gap", test_tables), &
         new_unittest("--max-contacts above MAXCONT: the factor grows; the end state against an exact solve", &
            test_growth), &
         new_unittest("OpenMP: 1 and 2 threads, FFT event search and cg", test_threads), &
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
         options%solver = SOLVER_INCREMENTAL
         call solve_contact(deck, options, inc, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         options%solver = SOLVER_LEGACY
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
         ! Two solvers of one model: the legacy skyline with its refinement step agrees with
         ! the condensed factor to ~1e-10 (doc/stability.md); 1e-9 leaves a decade.
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

   !> Independent reference for the event path itself (issue 34, section 6: the test above
   !> compares two of femcod's solvers): test/oracles' event_path, a brute-force stepping
   !> with two dense LU solves per event and direct-sum gaps from the quadruple-precision
   !> Love table, on the 2 nm and 1 nm spheres of input/ (to 18000 nN) and the rough 32^2
   !> deck (to MAXCONT). The incremental solver's distinct event loads and contact counts
   !> equal the oracle's, the loads within 1e-9 relative (the condensed factor's
   !> round-off, doc/stability.md, is 1e-10).
   subroutine test_oracle_events(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: decks(3) = [character(len=20) :: "sphere_d2", "sphere_d1", "rough_selfaffine_32"]
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc
      type(status_type) :: status
      real(dp), allocatable :: table(:, :), oracle_loads(:), li(:)
      integer, allocatable :: oracle_counts(:), ci(:)
      real(dp) :: worst, top
      integer :: d, m, mi, k, n
      logical :: released
      do d = 1, size(decks)
         call read_deck("input/"//trim(decks(d))//".deck", deck, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         top = huge(1.0_dp)
         options = contact_options()
         options%solver = SOLVER_INCREMENTAL
         if (index(decks(d), "sphere") > 0) then
            top = 18000
            options%loads = [top]
         end if
         call solve_contact(deck, options, inc, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         allocate(li(inc%nsteps), ci(inc%nsteps), oracle_loads(deck%maxcont + 1), oracle_counts(deck%maxcont + 1))
         call events(inc, li, ci, mi)
         table = love_table(deck%np)
         call event_path(deck, table, 1.0e-9_dp, deck%maxcont + 1, top, oracle_loads, oracle_counts, m, released)
         call check(error, .not. released, trim(decks(d))//": the oracle's path needs a release")
         if (allocated(error)) return
         ! History row k: the contacts of step k and the load at which it ends (the next
         ! contact closes), as the oracle's events; those up to the requested load.
         n = 0
         worst = 0
         do k = 1, mi
            if (li(k) > top) exit
            n = n + 1
            if (n > m) exit
            call check(error, ci(k), oracle_counts(n), trim(decks(d))//": contacts at event "//to_string(n))
            if (allocated(error)) return
            worst = max(worst, abs(li(k) - oracle_loads(n))/oracle_loads(n))
         end do
         call check(error, n == m .and. m >= 4, trim(decks(d))//": "//to_string(n)//" events of the solver, "// &
            to_string(m)//" of the oracle")
         if (allocated(error)) return
         call check(error, worst < 1.0e-9_dp, trim(decks(d))//": event loads within 1e-9 of the oracle's, worst "// &
            to_string(worst))
         if (allocated(error)) return
         deallocate(li, ci, oracle_loads, oracle_counts)
      end do
   end subroutine test_oracle_events

   !> Independent reference: Kalker-style fixed-load active-set iteration with the
   !> oracles' dense LU solve and direct-sum gaps (test/oracles): start from the pixels
   !> that touch first, drop the most tensile contact or add the most penetrating pixel
   !> until neither exists. A different algorithm from the event stepping.
   subroutine test_active_set(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc
      type(status_type) :: status
      real(dp), allocatable :: g0(:, :), table(:, :), f(:), gap(:, :)
      integer, allocatable :: ic(:), jc(:), pix(:)
      logical, allocatable :: active(:, :)
      real(dp) :: a, load
      integer :: np, p, n, it, k, idx, l, info, worst(2)
      real(dp), parameter :: loads(3) = [300.0_dp, 2000.0_dp, 8000.0_dp]
      call read_deck("input/rough_selfaffine_32.deck", deck, status)
      ! Rigid springs: contact modulus so large that 3/k is below round-off of c.
      deck%young(3) = 1.0e25_dp
      np = deck%np
      options%loads = loads
      options%solver = SOLVER_INCREMENTAL
      call solve_contact(deck, options, inc, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      g0 = reference_gaps(deck)
      table = love_table(np)
      do l = 1, size(loads)
         load = loads(l)
         active = g0 <= minval(g0) + 1.0e-9_dp
         do it = 1, 10*np*np
            n = count(active)
            pix = pack([(p, p = 1, np*np)], reshape(transpose(active), [np*np]))
            ic = (pix - 1)/np + 1
            jc = pix - (ic - 1)*np
            if (allocated(f)) deallocate(f)
            allocate(f(n))
            call exact_state(deck, table, ic, jc, load, f, a, info)
            if (minval(f) < 0) then
               idx = minloc(f, 1)
               active(ic(idx), jc(idx)) = .false.
               cycle
            end if
            gap = gaps_at_state(deck, table, ic, jc, f, a)
            where (active) gap = 0
            if (minval(gap) >= 0) exit
            worst = minloc(gap)
            active(worst(1), worst(2)) = .true.
         end do
         call check(error, inc%states(l)%contacts, n, "contacts at "//to_string(nint(load))//" nN")
         if (allocated(error)) return
         call check(error, inc%states(l)%approach, a, rel=.true., thr=1.0e-10_dp, &
            message="approach at "//to_string(nint(load))//" nN")
         if (allocated(error)) return
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

   !> Tables 4.1 and 4.2 (finest meshes, femcod_thesis) within the thesis' printing
   !> (0.5 %), and the state at 1 nN against the oracles: the exact forces and approach of
   !> the solver's contact set (a dense LU solve, test/oracles) to 1e-10, and no pixel
   !> outside it penetrating by more than 1e-12 of the height range (direct sums with
   !> quadruple-precision Love coefficients).
   subroutine test_tables(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc
      type(status_type) :: status
      character(len=*), parameter :: decks(2) = [character(len=16) :: "circle_punch_d9", "square_punch_n27"]
      real(dp), parameter :: thesis(2) = [TABLE_4_1_APPROACH(3), TABLE_4_2_APPROACH(4)]
      integer :: k
      do k = 1, 2
         call read_deck("input/"//trim(decks(k))//".deck", deck, status)
         options%loads = [1.0_dp]
         options%solver = SOLVER_INCREMENTAL
         call solve_contact(deck, options, inc, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         call check(error, inc%states(1)%approach, thesis(k), rel=.true., thr=5.0e-3_dp, message=trim(decks(k)))
         if (allocated(error)) return
         call check_against_oracles(error, trim(decks(k)), deck, inc, 1.0_dp)
         if (allocated(error)) return
      end do
   end subroutine test_tables

   !> The contacts and forces a result reports at `load` (its largest requested load, or
   !> the end of the run) against test/oracles: the same contact set solved exactly, and
   !> every other pixel's gap under the reported forces.
   subroutine check_against_oracles(error, name, deck, res, load)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: name
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      real(dp), intent(in) :: load
      real(dp), allocatable :: table(:, :), forces(:), gap(:, :)
      real(dp) :: approach, reported, range
      integer :: info, k
      table = love_table(deck%np)
      allocate(forces(size(res%contact_i)))
      call exact_state(deck, table, res%contact_i, res%contact_j, load, forces, approach, info)
      call check(error, info, 0, name//": the oracle's solve")
      if (allocated(error)) return
      call check(error, maxval(abs(res%contact_force - forces)) <= 1.0e-10_dp*maxval(abs(forces)), name// &
         ": forces against the exact solve, "//to_string(maxval(abs(res%contact_force - forces))/maxval(abs(forces))))
      if (allocated(error)) return
      reported = res%step_approach(res%nsteps)
      if (size(res%states) > 0) reported = res%states(size(res%states))%approach
      call check(error, reported, approach, rel=.true., thr=1.0e-10_dp, message=name//": approach")
      if (allocated(error)) return
      gap = gaps_at_state(deck, table, res%contact_i, res%contact_j, res%contact_force, reported)
      do k = 1, size(res%contact_i)
         gap(res%contact_i(k), res%contact_j(k)) = huge(1.0_dp)
      end do
      range = maxval(deck%lower) - minval(deck%lower) + maxval(deck%upper) - minval(deck%upper)
      call check(error, minval(gap) >= -1.0e-12_dp*range, name//": deepest penetration outside the contacts "// &
         to_string(-minval(gap)))
   end subroutine check_against_oracles

   !> --max-contacts 600 in place of the deck's MAXCONT of 100 (the option replaces it,
   !> doc/solver.md): the factor's storage doubles from 256 to 1024 columns on the way to
   !> 600 contacts; the end state against the oracles, no tensile force.
   subroutine test_growth(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: inc
      type(status_type) :: status
      call read_deck("input/rough_selfaffine_32.deck", deck, status)
      call check(error, deck%maxcont, 100, "the deck's MAXCONT")
      if (allocated(error)) return
      options%max_contacts = 600
      allocate(options%loads(0))
      options%solver = SOLVER_INCREMENTAL
      call solve_contact(deck, options, inc, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call check(error, size(inc%contact_i) > 512, "more contacts than two doublings: "//to_string(size(inc%contact_i)))
      if (allocated(error)) return
      call check_against_oracles(error, "600 contacts", deck, inc, inc%reported_load)
      if (allocated(error)) return
      call check(error, all(inc%contact_force >= 0), "no tensile force")
   end subroutine test_growth

   !> OpenMP with 1 and 2 threads on a 64 x 64 rough surface: the incremental solver
   !> with the full-field event search (the convolution's three passes run in parallel
   !> blocks, each line's transform on its own) gives the same events bit for bit; the
   !> cg solver (parallel loops with reductions, whose order changes with the threads)
   !> the same contacts and the approach to 1e-10.
   subroutine test_threads(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res(2), cg(2)
      type(status_type) :: status
      real(dp), allocatable :: t(:, :, :)
      integer :: saved, k
      spec%kind = "self-affine"
      spec%np = 64
      spec%pixel = 10
      spec%rms = 3
      spec%seed = 3
      spec%shape_on = "lower"
      spec%label = "threads"
      spec%matrix_file = ""
      spec%maxcont = 150
      call build_problem(spec, deck, status)
      call check(error, status%code, 0, "the scene: "//status%message)
      if (allocated(error)) return
      saved = omp_get_max_threads()
      allocate(t(0:63, 0:63, 2))
      do k = 1, 2
         call omp_set_num_threads(k)
         call check(error, omp_get_max_threads(), k, "threads set")
         if (allocated(error)) exit
         t(:, :, k) = offset_table(64)
         options%solver = SOLVER_INCREMENTAL
         options%event_search = "fft"
         allocate(options%loads(0))
         call solve_contact(deck, options, res(k), status)
         call check(error, status%code, 0, "incremental, "//to_string(k)//" threads: "//status%message)
         if (allocated(error)) exit
         options%solver = SOLVER_CG
         options%loads = [res(k)%step_load(res(k)%nsteps)/2]
         call solve_contact(deck, options, cg(k), status)
         deallocate(options%loads)
      end do
      call omp_set_num_threads(saved)
      if (allocated(error)) return
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, all(t(:, :, 1) == t(:, :, 2)), "offset table bit for bit")
      if (allocated(error)) return
      call check(error, res(1)%nsteps == res(2)%nsteps .and. fft_steps_of(res(1)) == res(1)%nsteps, "full-field steps")
      if (allocated(error)) return
      call check(error, all(res(1)%step_contacts(1:res(1)%nsteps) == res(2)%step_contacts(1:res(1)%nsteps)) .and. &
         all(res(1)%step_load(1:res(1)%nsteps) == res(2)%step_load(1:res(1)%nsteps)), "same events, bit for bit")
      if (allocated(error)) return
      call check(error, cg(1)%states(1)%contacts, cg(2)%states(1)%contacts, "cg: contacts")
      if (allocated(error)) return
      call check(error, cg(2)%states(1)%approach, cg(1)%states(1)%approach, rel=.true., thr=1.0e-10_dp, &
         message="cg: approach")
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
         options%solver = SOLVER_INCREMENTAL
         call solve_contact(deck, options, a, status)
         options%event_search = "fft"
         options%solver = SOLVER_INCREMENTAL
         call solve_contact(deck, options, b, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         n = a%nsteps
         call check(error, b%nsteps == n .and. fft_steps_of(b) == n .and. fft_steps_of(a) == 0, &
            trim(VERIFICATION_DECKS(d))//": steps and search counts")
         if (allocated(error)) return
         call check(error, all(a%step_contacts(1:n) == b%step_contacts(1:n)), trim(VERIFICATION_DECKS(d))// &
            ": contacts at every step")
         if (allocated(error)) return
         call check(error, maxval(abs(a%step_load(1:n) - b%step_load(1:n))) <= 1.0e-12_dp*maxval(a%step_load(1:n)), &
            trim(VERIFICATION_DECKS(d))//": loads")
         if (allocated(error)) return
      end do
      ! Auto: the same events as the bound search on the last deck.
      options%event_search = "auto"
      options%solver = SOLVER_INCREMENTAL
      call solve_contact(deck, options, b, status)
      call check(error, b%nsteps == a%nsteps, "auto: steps")
      if (allocated(error)) return
      call check(error, all(a%step_contacts(1:n) == b%step_contacts(1:n)) .and. &
         maxval(abs(a%step_load(1:n) - b%step_load(1:n))) <= 1.0e-12_dp*maxval(a%step_load(1:n)), "auto: events")
      if (allocated(error)) return
      ! Auto's rule against its cost model, worked by hand at NP = 512 (M = 1024,
      ! M^2 log2 M^2 = 2.10e7 point-levels, two convolutions 0.210 s): 2e-9 s per
      ! evaluation and contact, so with n = 2000 contacts the bound search costs
      ! 4e-6 s per evaluated pixel: 20000 evaluations (0.08 s) keep it, 100000 (0.4 s) do
      ! not; every 16th step, and with no contacts, the bound search runs.
      call check(error, .not. fft_search_pays(512, 2000, 20000, 5), "auto keeps the bound search when it is cheap")
      if (allocated(error)) return
      call check(error, fft_search_pays(512, 2000, 100000, 5), "auto takes the full field when it is cheaper")
      if (allocated(error)) return
      call check(error, .not. fft_search_pays(512, 2000, 100000, 32), "every 16th step by the bound")
      if (allocated(error)) return
      call check(error, .not. fft_search_pays(512, 0, 100000, 5), "no contacts: no full field")
   end subroutine test_event_search
end module test_incremental
