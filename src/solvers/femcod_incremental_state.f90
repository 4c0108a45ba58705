!> The state of the event-exact incremental solver (solvers/femcod_incremental) in one
!> type, with the operations the algorithm of doc/solver.md names: border the factor
!> with a new contact, release one, refill the candidate cache, evaluate a pixel, and
!> the solution under a unit load increment.
!>
!> With both handles and the springs eliminated, the contacts C carry forces F with
!>     M F - A 1 = -g0_C,   1'F = P,     M = c I_CC + s Id,
!> c = c1 + c2 the composite surface compliance (one Love table serves both bodies), s
!> the compliance of the springs in series at a contact (two interface springs and the
!> penalty spring, 3/k). Under a unit load increment f = M^-1 1/(1'M^-1 1) and the
!> approach rate is delta = 1/(1'M^-1 1). M = U'U is kept as a Cholesky factor in full
!> column storage that grows by doubling; a new contact borders it with one column
!> l = U^-T m, never a refactorisation, except when a contact is released. l and
!> w = M^-1 m of the next contact usually come from a cache of the candidates predicted
!> to close next, kept current in O(n) each per contact and refilled with BLAS-3 solves;
!> x = M^-1 1 is updated from w, so a normal event streams no factor.
!>
!> Everything that continues a run bit for bit is listed once in `visit` (checkpoints,
!> io/femcod_checkpoint); the rest is rebuilt from the problem by `init` and `rebuild`.
module femcod_incremental_state
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_BAD_INPUT
   use femcod_strings, only: int_str
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gaps, initial_gap_map
   use femcod_elastic_operator, only: grid_operator, grid_operator_setup, grid_operator_free, TABLE_DOUBLE
   use femcod_lapack, only: dtrsv, dtrsm
   use femcod_condensed, only: gap_and_rate
   use femcod_heap, only: min_heap, heap_build, heap_push
   use femcod_sort, only: merge_sort_index
   use femcod_memory, only: memory_text, usable_text
   use femcod_state_visitor, only: state_visitor, visitable
   use femcod_solver_options, only: contact_options, cg_settings, &
      BOUNDARY_PERIODIC
   use femcod_contact_result, only: contact_result, visit_result, event_path_diagnostics, visit_event_checks
   use femcod_event_path, only: load_path
   use femcod_interface_law, only: interface_law, make_interface_law
   implicit none
   private
   public :: incremental_state, CACHE_SIZE, REFILL_EVERY, factor_peak_bytes

   !> Candidates whose bordering columns l = U^-T m and w = M^-1 m are kept up to date
   !> (O(n) each per new contact), and how many contacts join between refills of the
   !> cache (one pair of BLAS-3 triangular solves for the new candidates).
   integer, parameter :: CACHE_SIZE = 128, REFILL_EVERY = 64

   type, extends(visitable) :: incremental_state
      !> The problem as the solver sees it (set by `init`, never stored): pixels per side,
      !> pixels, the most contacts, cache slots; composite compliance c (nm/nN), spring
      !> compliance s (nm/nN), a contact's self-compliance c I(0,0) + s (the operator's);
      !> the elastic operator, whose double Love table (op%exact) the exact evaluations read
      !> and whose convolution the searches and the final check take; the initial gaps
      !> (nm, pixel p = (i-1) NP + j).
      integer :: np = 0, npix = 0, maxc = 0, kc = 0
      real(dp) :: c = 0, s = 0, self = 0
      type(grid_operator) :: op
      real(dp), allocatable :: g0(:)
      !> The grid is one cell of a periodic surface (--boundary periodic); the smallest
      !> entry of the table if negative, else 0 (for the gap bound of unit_load).
      logical :: periodic = .false.
      real(dp) :: table_min = 0
      !> The bytes this run may use (options%memory_available; 0: not checked): the
      !> factor grows within it.
      integer(i8) :: memory_available = 0
      !> The plastic cap (--plastic): the force H d^2 (nN) a capped pixel carries (0: no
      !> cap). Capped pixels are out of the elastic set and the heap (slot -1); their
      !> forces are folded into g0 (c fmax I at every pixel), so the elastic problem is
      !> the thesis' one with other initial gaps. g0_deck keeps the deck's gaps.
      real(dp) :: fmax = 0
      integer :: nplastic = 0
      integer, allocatable :: plastic_pix(:), plastic_step(:)
      real(dp), allocatable :: g0_deck(:)
      !> Upper bounds on the capped pixels' gaps, plastic_key + psi (nm): psi grows by
      !> open_max (nm/nN), the fastest any gap can open, per unit of load (not stored in
      !> checkpoints: a bound of 0 is valid for a capped pixel, and exact evaluations
      !> decide every event, so a restart repeats the same events).
      real(dp), allocatable :: plastic_key(:)
      real(dp) :: psi = 0, open_max = 0
      !> Steps done, contacts n; per contact: row, column, pixel, step joined, total force
      !> (nN) and force per unit load increment; slot(p): the contact at pixel p (0: none).
      integer :: step = 0, n = 0
      integer, allocatable :: ic(:), jc(:), pix(:), cstep(:), slot(:)
      real(dp), allocatable :: ftot(:), funit(:)
      !> The factor U (ld x ld storage), y = U^-T 1, x = M^-1 1; work columns.
      integer :: ld = 0
      real(dp), allocatable :: u(:, :), y(:), x(:), col(:), wq(:)
      !> The candidate cache: slot -> pixel (0: empty), pixel -> slot, columns l and w per
      !> slot, each pixel's predicted closing load (nN, from its last exact evaluation),
      !> contacts joined since the last refill.
      integer, allocatable :: cpix(:), cslot(:)
      real(dp), allocatable :: lc(:, :), wc(:, :), pred(:)
      integer :: since_refill = 0
      !> Total load and approach; phi (nm): how far the heap's gap bounds have moved;
      !> approach rate delta (nm/nN) and the fastest any gap can close, delta_max.
      type(load_path) :: path
      real(dp) :: phi = 0, delta = 0, delta_max = 0
      !> Every pixel not in contact keyed by a lower bound on its gap (plus phi); the exact
      !> evaluations of the last bound search (for the choice of the event search).
      type(min_heap) :: heap
      integer :: last_neval = 0
      !> The results so far.
      type(contact_result) :: res
      !> What the event path found and counted (the result's diagnostics at the end).
      type(event_path_diagnostics) :: checks
   contains
      procedure :: init
      procedure :: visit
      procedure :: rebuild
      procedure :: unit_load
      procedure :: evaluate
      procedure :: add_contact
      procedure :: release_contact
      procedure :: cap_contact
      procedure :: uncap_pixel
      procedure :: refill_cache
   end type incremental_state

contains

   !> The state at zero load, before the first contact: tables, storage, every pixel in
   !> the heap keyed by its exact gap.
   !> The most memory the contact storage takes at `maxc` contacts (bytes): the factor U
   !> (8 maxc^2, square storage) and, while the last doubling copies it, the factor it
   !> grew from (8 (maxc/2)^2 at least); the candidate cache's two column blocks of up to
   !> CACHE_SIZE columns (twice, during that copy); ten per-contact vectors. Pixel arrays
   !> (the gaps, the heap, the FFT buffers: O(NP^2)) are small beside it at any MAXCONT
   !> where this matters and are left out.
   pure function factor_peak_bytes(maxc, npix) result(bytes)
      integer, intent(in) :: maxc, npix
      integer(i8) :: bytes, m, kc, old
      m = maxc
      kc = min(CACHE_SIZE, npix)
      old = (m + 1)/2
      bytes = 8*m**2 + 8*old**2 + 2*(2*8*m*kc) + 10*8*m
   end function factor_peak_bytes

   subroutine init(self, problem, options)
      class(incremental_state), intent(out) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      integer, allocatable :: items(:)
      integer :: p
      type(interface_law) :: law
      type(cg_settings) :: plain
      call self%path%start(problem, options, self%res)
      self%np = problem%np
      self%npix = self%np*self%np
      self%maxc = self%path%max_contacts
      self%periodic = options%boundary == BOUNDARY_PERIODIC
      self%memory_available = options%memory_available
      ! The whole kernel, double transforms by estimated plans, no preconditioner: the
      ! event solvers' convolution; the double table kept.
      plain%single_until = 0
      plain%precondition = .false.
      call grid_operator_setup(self%op, initial_gap_map(problem%lower, problem%upper), problem, problem%pixel, &
         plain, self%periodic, tables=TABLE_DOUBLE)
      ! The most negative influence (a periodic table's, whose mean is 0; none free).
      self%table_min = min(minval(self%op%exact), 0.0_dp)
      self%g0 = initial_gaps(problem%lower, problem%upper)
      self%fmax = 0
      self%nplastic = 0
      allocate(self%plastic_pix(0), self%plastic_step(0), self%plastic_key(0))
      ! The cap from the one description of the interface (femcod_interface_law) that the
      ! cg paths read too; the event path reaches it by its own exact yield events.
      law = make_interface_law(options%adhesion, options%work, options%range, problem%pixel, options%plastic, &
         options%hardness)
      if (law%capped()) then
         self%fmax = law%fmax
         self%g0_deck = self%g0
         allocate(self%res%step_plastic(0))
      end if
      self%c = self%op%c
      self%s = self%op%s
      self%self = self%c*self%op%exact(0, 0) + self%s
      self%ld = min(self%maxc, 256)
      self%kc = min(CACHE_SIZE, self%npix)
      allocate(self%u(self%ld, self%ld), self%lc(self%ld, self%kc), self%wc(self%ld, self%kc))
      associate(m => self%maxc)
         allocate(self%ic(m), self%jc(m), self%pix(m), self%cstep(m), self%ftot(m), self%funit(m), self%y(m), &
            self%x(m), self%col(m), self%wq(m))
      end associate
      allocate(self%slot(self%npix), self%cpix(self%kc), self%cslot(self%npix), self%pred(self%npix))
      self%slot = 0
      self%cpix = 0
      self%cslot = 0
      self%pred = huge(1.0_dp)
      allocate(items(self%npix))
      do p = 1, self%npix
         items(p) = p
      end do
      ! Room for stale entries: a pixel found by the FFT search joins without leaving the
      ! heap, and a released contact is pushed back.
      call heap_build(self%heap, self%g0, items, 2*self%npix)
   end subroutine init

   !> Every field that continues the run, once, in a fixed order (femcod_state_visitor).
   subroutine visit(self, visitor)
      class(incremental_state), intent(inout) :: self
      class(state_visitor), intent(inout) :: visitor
      call visitor%group("state")
      call visitor%integer_value("step", self%step)
      call visitor%integer_value("n", self%n)
      call visitor%real_value("total", self%path%total)
      call visitor%real_value("approach", self%path%approach)
      call visitor%real_value("phi", self%phi)
      call visitor%integer_prefix("pix", self%pix, self%n)
      call visitor%integer_prefix("cstep", self%cstep, self%n)
      call visitor%real_prefix("ftot", self%ftot, self%n)
      call visitor%integer_value("ld", self%ld)
      ! A reader may have read another storage size of the factor: make the storage fit.
      if (visitor%status%code == 0 .and. size(self%u, 1) /= self%ld) call resize_factor(self, self%ld, .false.)
      call visitor%real_triangle("factor", self%u, self%n)
      call visitor%real_prefix("y", self%y, self%n)
      call visitor%real_prefix("x", self%x, self%n)
      call visitor%integer_prefix("cache_pixel", self%cpix, self%kc)
      call visitor%real_rows("cache_l", self%lc, self%n)
      call visitor%real_rows("cache_w", self%wc, self%n)
      call visitor%real_prefix("predicted", self%pred, self%npix)
      call visitor%integer_value("since_refill", self%since_refill)
      call visitor%integer_value("last_neval", self%last_neval)
      call visitor%integer_value("heap_size", self%heap%size)
      call visitor%real_prefix("heap_key", self%heap%key, self%heap%size)
      call visitor%integer_prefix("heap_item", self%heap%item, self%heap%size)
      call visit_result(self%res, visitor)
      call visit_event_checks(self%checks, visitor)
      if (self%fmax > 0) then
         ! The plastic set (runs without the cap store nothing more, as before it).
         call visitor%group("plastic")
         call visitor%integer_value("nplastic", self%nplastic)
         if (visitor%status%code /= 0) return
         if (size(self%plastic_pix) /= self%nplastic) then
            deallocate(self%plastic_pix, self%plastic_step)
            allocate(self%plastic_pix(max(self%nplastic, 0)), self%plastic_step(max(self%nplastic, 0)))
         end if
         call visitor%integer_prefix("pixel", self%plastic_pix, self%nplastic)
         call visitor%integer_prefix("step", self%plastic_step, self%nplastic)
         if (.not. allocated(self%res%step_plastic)) allocate(self%res%step_plastic(0))
         if (size(self%res%step_plastic) /= self%res%nsteps) then
            deallocate(self%res%step_plastic)
            allocate(self%res%step_plastic(max(self%res%nsteps, 0)))
         end if
         call visitor%integer_prefix("step_plastic", self%res%step_plastic, self%res%nsteps)
      end if
   end subroutine visit

   !> After a reader filled the stored fields: check them against the problem and derive
   !> the indices (rows and columns, pixel -> contact and pixel -> cache slot).
   subroutine rebuild(self, status)
      class(incremental_state), intent(inout) :: self
      type(status_type), intent(inout) :: status
      integer :: k
      if (self%n < 1 .or. self%n > self%maxc .or. self%ld < self%n .or. self%ld > self%maxc .or. &
         any(self%pix(1:self%n) < 1) .or. any(self%pix(1:self%n) > self%npix) .or. &
         any(self%cpix < 0) .or. any(self%cpix > self%npix) .or. &
         any(self%heap%item(1:self%heap%size) < 1) .or. any(self%heap%item(1:self%heap%size) > self%npix) .or. &
         self%res%nsteps /= self%step) then
         call set_error(status, STATUS_BAD_INPUT, "the stored state is inconsistent (corrupted)")
         return
      end if
      self%slot = 0
      do k = 1, self%n
         self%ic(k) = (self%pix(k) - 1)/self%np + 1
         self%jc(k) = self%pix(k) - (self%ic(k) - 1)*self%np
         self%slot(self%pix(k)) = k
      end do
      self%cslot = 0
      do k = 1, self%kc
         if (self%cpix(k) > 0) self%cslot(self%cpix(k)) = k
      end do
      ! The capped pixels: out of the elastic set, their forces back in the gaps.
      if (self%fmax > 0) then
         if (any(self%plastic_pix(1:self%nplastic) < 1) .or. any(self%plastic_pix(1:self%nplastic) > self%npix)) then
            call set_error(status, STATUS_BAD_INPUT, "the stored state is inconsistent (corrupted)")
            return
         end if
         self%g0 = self%g0_deck
         self%psi = 0
         self%plastic_key = [(0.0_dp, k = 1, self%nplastic)]
         do k = 1, self%nplastic
            if (self%slot(self%plastic_pix(k)) /= 0) then
               call set_error(status, STATUS_BAD_INPUT, "the stored state is inconsistent (corrupted)")
               return
            end if
            self%slot(self%plastic_pix(k)) = -1
            call fold_force(self, self%plastic_pix(k), self%fmax)
         end do
      end if
   end subroutine rebuild

   !> The solution under a unit load increment: x = M^-1 1 (kept current by add_contact),
   !> beta = 1'x = y'y, delta = 1/beta, funit = x delta, and the fastest closing rate of
   !> any gap, delta_max = delta + c I(0,0) sum_k max(-funit_k, 0) (since F >= 0)
   !> + c |min I| sum_k max(funit_k, 0) (0 for the free table, positive everywhere;
   !> a periodic table has negative entries, through which growing forces lift others).
   pure subroutine unit_load(self)
      class(incremental_state), intent(inout) :: self
      real(dp) :: beta
      associate(n => self%n)
         beta = sum(self%y(1:n)**2)
         self%delta = 1/beta
         self%funit(1:n) = self%x(1:n)*self%delta
         self%delta_max = self%delta + self%c*self%op%exact(0, 0)*sum(max(-self%funit(1:n), 0.0_dp))
         if (self%table_min < 0) self%delta_max = self%delta_max - self%c*self%table_min*sum(max(self%funit(1:n), 0.0_dp))
         ! The fastest any gap can open: c I sum f - delta, with I at most I(0, 0) where
         ! f > 0 and at least min I where f < 0.
         if (self%fmax > 0) self%open_max = max(0.0_dp, self%c*self%op%exact(0, 0)*sum(max(self%funit(1:n), 0.0_dp)) - &
            self%c*self%table_min*sum(max(-self%funit(1:n), 0.0_dp)) - self%delta)
      end associate
   end subroutine unit_load

   !> Exact gap (nm) of a pixel not in contact and its closing rate (nm/nN) under the
   !> unit load increment: O(n).
   pure subroutine evaluate(self, pixel, gap, closing)
      class(incremental_state), intent(in) :: self
      integer, intent(in) :: pixel
      real(dp), intent(out) :: gap, closing
      integer :: ip, jp
      associate(n => self%n)
         ip = (pixel - 1)/self%np + 1
         jp = pixel - (ip - 1)*self%np
         call gap_and_rate(self%g0(pixel), self%path%approach, self%delta, self%c, self%op%exact, ip, jp, &
            self%ic(1:n), self%jc(1:n), self%ftot(1:n), self%funit(1:n), gap, closing)
      end associate
   end subroutine evaluate

   !> Border the factor with a new contact at `pixel` (zero force), joined at step
   !> `joined`: U gains a column (Uk = U^-T m, diagonal sqrt(mu - |Uk|^2)) and
   !> y = U^-T 1 one entry.
   subroutine add_contact(self, pixel, joined, status)
      class(incremental_state), intent(inout) :: self
      integer, intent(in) :: pixel, joined
      type(status_type), intent(inout) :: status
      integer :: ip, jp, kk, sq, ss, ipp, jpp
      real(dp) :: d2, dq, tt
      integer(i8) :: grown
      if (self%n + 1 > self%ld) then
         ! Grow the factor's storage by doubling (amortised O(n^2) copies), within the
         ! machine's memory (Linux would over-commit and kill the run later).
         grown = min(2*self%ld, self%maxc)
         if (self%memory_available > 0 .and. 8*grown**2 > self%memory_available) then
            call set_error(status, STATUS_NUMERICAL, "incremental: the factor for "// &
               int_str(int(grown))//" contacts needs "//memory_text(8*grown**2)//", this run may use "// &
               usable_text(self%memory_available)//"; lower MAXCONT or --max-contacts")
            return
         end if
         call resize_factor(self, int(grown), .true., status)
         if (status%code /= 0) return
      end if
      associate(n => self%n, u => self%u, col => self%col, wq => self%wq, np => self%np)
         ip = (pixel - 1)/np + 1
         jp = pixel - (ip - 1)*np
         sq = self%cslot(pixel)
         if (sq > 0) then
            ! A cached candidate: its columns are ready.
            col(1:n) = self%lc(1:n, sq)
            wq(1:n) = self%wc(1:n, sq)
            self%cslot(pixel) = 0
            self%cpix(sq) = 0
            self%checks%cache_hits = self%checks%cache_hits + 1
         else
            ! l = U^-T m and w = U^-1 l = M^-1 m by two triangular solves.
            do kk = 1, n
               col(kk) = self%c*self%op%exact(abs(ip - self%ic(kk)), abs(jp - self%jc(kk)))
            end do
            if (n > 0) call dtrsv("U", "T", "N", n, u, self%ld, col, 1)
            wq(1:n) = col(1:n)
            if (n > 0) call dtrsv("U", "N", "N", n, u, self%ld, wq, 1)
            self%checks%cache_misses = self%checks%cache_misses + 1
         end if
         d2 = self%self - sum(col(1:n)**2)
         if (.not. d2 > epsilon(1.0_dp)*self%self) then
            call set_error(status, STATUS_NUMERICAL, "incremental: the contact compliance lost positive definiteness")
            return
         end if
         dq = sqrt(d2)
         ! Every cached candidate p follows: l_p gains (mu_pq - l_q'l_p)/d, and
         ! w_p = M^-1 m_p becomes [w_p - w_q t; t], t = (mu_pq - l_q'l_p)/d^2 (the bordered
         ! inverse). Slots are independent: the same bits for any number of threads.
         !$omp parallel do schedule(static) private(ss, ipp, jpp, tt) if (n > 200000)
         do ss = 1, self%kc
            if (self%cpix(ss) == 0) cycle
            ipp = (self%cpix(ss) - 1)/np + 1
            jpp = self%cpix(ss) - (ipp - 1)*np
            tt = (self%c*self%op%exact(abs(ipp - ip), abs(jpp - jp)) - dot_product(col(1:n), self%lc(1:n, ss)))/dq
            self%lc(n + 1, ss) = tt
            self%wc(1:n, ss) = self%wc(1:n, ss) - wq(1:n)*(tt/dq)
            self%wc(n + 1, ss) = tt/dq
         end do
         !$omp end parallel do
         u(1:n, n + 1) = col(1:n)
         u(n + 1, n + 1) = dq
         self%y(n + 1) = (1 - sum(col(1:n)*self%y(1:n)))/dq
         ! x = M^-1 1 = U^-1 y: [x - w_q eta/d; eta/d] with eta the new entry of y.
         self%x(1:n) = self%x(1:n) - wq(1:n)*(self%y(n + 1)/dq)
         self%x(n + 1) = self%y(n + 1)/dq
         n = n + 1
         self%ic(n) = ip
         self%jc(n) = jp
         self%pix(n) = pixel
         self%cstep(n) = joined
         self%ftot(n) = 0
         self%slot(pixel) = n
      end associate
   end subroutine add_contact

   !> New storage of leading dimension `ld` for the factor and the cached columns;
   !> `keep`: copy the n columns there are.
   subroutine resize_factor(self, ld, keep, status)
      type(incremental_state), intent(inout) :: self
      integer, intent(in) :: ld
      logical, intent(in) :: keep
      type(status_type), intent(inout), optional :: status
      real(dp), allocatable :: bigger(:, :)
      integer :: stat
      allocate(bigger(ld, ld), stat=stat)
      if (stat /= 0) then
         if (present(status)) call set_error(status, STATUS_NUMERICAL, "incremental: cannot allocate the factor for "// &
            int_str(ld)//" contacts ("//memory_text(8*int(ld, i8)**2)//")")
         return
      end if
      if (keep) bigger(1:self%n, 1:self%n) = self%u(1:self%n, 1:self%n)
      call move_alloc(bigger, self%u)
      self%ld = ld
      allocate(bigger(ld, self%kc))
      if (keep) bigger(1:self%n, :) = self%lc(1:self%n, :)
      call move_alloc(bigger, self%lc)
      allocate(bigger(ld, self%kc))
      if (keep) bigger(1:self%n, :) = self%wc(1:self%n, :)
      call move_alloc(bigger, self%wc)
   end subroutine resize_factor

   !> Remove contact k (its force is zero; remove_contact); the pixel goes back into the
   !> heap at the current bound offset.
   subroutine release_contact(self, krm, status)
      class(incremental_state), intent(inout) :: self
      integer, intent(in) :: krm
      type(status_type), intent(inout) :: status
      self%ftot(krm) = 0
      self%slot(self%pix(krm)) = 0
      call heap_push(self%heap, self%phi, self%pix(krm))
      call remove_contact(self, krm, status)
      self%checks%releases = self%checks%releases + 1
   end subroutine release_contact

   !> Contact k has reached the cap fmax = H d^2: it leaves the elastic set (the factor
   !> shrinks by a column, remove_contact) and keeps fmax, folded into every pixel's
   !> g0. A periodic table's negative entries lower some gaps by up to c fmax |min K|:
   !> the heap's bounds move by that much (phi).
   subroutine cap_contact(self, k, joined, status)
      class(incremental_state), intent(inout) :: self
      integer, intent(in) :: k, joined
      type(status_type), intent(inout) :: status
      integer :: pixel
      pixel = self%pix(k)
      self%slot(pixel) = -1
      call remove_contact(self, k, status)
      if (status%code /= 0) return
      self%nplastic = self%nplastic + 1
      self%plastic_pix = [self%plastic_pix(1:self%nplastic - 1), pixel]
      self%plastic_step = [self%plastic_step(1:self%nplastic - 1), joined]
      ! Its gap is -s fmax <= 0 now.
      self%plastic_key = [self%plastic_key(1:self%nplastic - 1), -self%psi]
      call fold_force(self, pixel, self%fmax)
      self%phi = self%phi - self%c*self%fmax*self%table_min
   end subroutine cap_contact

   !> Capped pixel `pixel` has unloaded to zero gap: it rejoins the elastic set as a
   !> contact carrying fmax (its force leaves g0, which lowers gaps by up to c fmax I(0,0):
   !> the heap's bounds move by that much).
   subroutine uncap_pixel(self, pixel, joined, status)
      class(incremental_state), intent(inout) :: self
      integer, intent(in) :: pixel, joined
      type(status_type), intent(inout) :: status
      integer :: q
      q = findloc(self%plastic_pix(1:self%nplastic), pixel, 1)
      if (q == 0) return
      call fold_force(self, pixel, -self%fmax)
      self%phi = self%phi + self%c*self%fmax*self%op%exact(0, 0)
      self%plastic_pix = [self%plastic_pix(1:q - 1), self%plastic_pix(q + 1:self%nplastic)]
      self%plastic_step = [self%plastic_step(1:q - 1), self%plastic_step(q + 1:self%nplastic)]
      self%plastic_key = [self%plastic_key(1:q - 1), self%plastic_key(q + 1:self%nplastic)]
      self%nplastic = self%nplastic - 1
      self%slot(pixel) = 0
      call self%add_contact(pixel, joined, status)
      if (status%code /= 0) return
      self%ftot(self%n) = self%fmax
   end subroutine uncap_pixel

   !> g0 += c f I(p - pixel) at every pixel p: a fixed force f (nN) at `pixel`.
   subroutine fold_force(self, pixel, f)
      type(incremental_state), intent(inout) :: self
      integer, intent(in) :: pixel
      real(dp), intent(in) :: f
      integer :: ip, jp, i, j
      ip = (pixel - 1)/self%np + 1
      jp = pixel - (ip - 1)*self%np
      !$omp parallel do private(j) if (self%npix > 65536)
      do i = 1, self%np
         do j = 1, self%np
            self%g0((i - 1)*self%np + j) = self%g0((i - 1)*self%np + j) + &
               self%c*f*self%op%exact(abs(i - ip), abs(j - jp))
         end do
      end do
      !$omp end parallel do
   end subroutine fold_force

   !> Take contact krm out of the elastic set: its column leaves the factor, which is made
   !> triangular again by Givens rotations (M = U'U stays the Cholesky factorisation of the
   !> remaining contacts: O(n^2), where a refactorisation would cost n^3/3), then
   !> y = U^-T 1 and x = U^-1 y afresh (two triangular solves).
   subroutine remove_contact(self, krm, status)
      type(incremental_state), intent(inout) :: self
      integer, intent(in) :: krm
      type(status_type), intent(inout) :: status
      integer :: a, j
      real(dp) :: r, t1, t2
      real(dp), allocatable :: cs(:), sn(:)
      associate(n => self%n, u => self%u)
         self%ic(krm:n - 1) = self%ic(krm + 1:n)
         self%jc(krm:n - 1) = self%jc(krm + 1:n)
         self%pix(krm:n - 1) = self%pix(krm + 1:n)
         self%cstep(krm:n - 1) = self%cstep(krm + 1:n)
         self%ftot(krm:n - 1) = self%ftot(krm + 1:n)
         ! Columns krm+1..n move left; the trailing block is then upper Hessenberg: the
         ! rotation of rows (j, j+1) zeroes the entry below the diagonal of column j.
         ! Column by column (contiguous): the rotations found so far, then its own.
         allocate(cs(krm:n), sn(krm:n))
         do j = krm, n - 1
            u(1:j + 1, j) = u(1:j + 1, j + 1)
            do a = krm, j - 1
               t1 = u(a, j)
               t2 = u(a + 1, j)
               u(a, j) = cs(a)*t1 + sn(a)*t2
               u(a + 1, j) = cs(a)*t2 - sn(a)*t1
            end do
            r = hypot(u(j, j), u(j + 1, j))
            if (.not. r > 0) then
               call set_error(status, STATUS_NUMERICAL, "incremental: the factor lost its diagonal when a "// &
                  "contact left the elastic set")
               return
            end if
            cs(j) = u(j, j)/r
            sn(j) = u(j + 1, j)/r
            u(j, j) = r
            u(j + 1, j) = 0
         end do
         n = n - 1
         do a = 1, n
            self%slot(self%pix(a)) = a
         end do
         self%y(1:n) = 1
         call dtrsv("U", "T", "N", n, u, self%ld, self%y, 1)
         self%x(1:n) = self%y(1:n)
         call dtrsv("U", "N", "N", n, u, self%ld, self%x, 1)
         ! The cached columns belonged to the old factor.
         do a = 1, self%kc
            if (self%cpix(a) > 0) self%cslot(self%cpix(a)) = 0
         end do
         self%cpix = 0
      end associate
   end subroutine remove_contact

   !> Refill the cache with the candidates predicted to close next (smallest predicted
   !> closing load from their last exact evaluation): the new ones get l = U^-T M_c and
   !> w = U^-1 l from two BLAS-3 triangular solves with all of them at once, which run
   !> at arithmetic speed where one triangular solve per contact streams the whole
   !> factor from memory.
   subroutine refill_cache(self)
      class(incremental_state), intent(inout) :: self
      integer, allocatable :: cand(:), rank(:), fresh(:)
      real(dp), allocatable :: block(:, :)
      logical, allocatable :: wanted(:)
      integer :: m, nfresh, a, b, sa, ia, ja
      associate(n => self%n, kc => self%kc, np => self%np)
         self%since_refill = 0
         m = 0
         do a = 1, self%npix
            if (self%slot(a) == 0 .and. self%pred(a) < huge(1.0_dp)) m = m + 1
         end do
         if (m == 0 .or. n == 0) return
         allocate(cand(m), rank(m))
         m = 0
         do a = 1, self%npix
            if (self%slot(a) == 0 .and. self%pred(a) < huge(1.0_dp)) then
               m = m + 1
               cand(m) = a
            end if
         end do
         call merge_sort_index(self%pred(cand), rank)
         allocate(wanted(kc), fresh(kc))
         wanted = .false.
         ! Keep cached candidates still among the best; evict the others.
         nfresh = 0
         do a = 1, min(kc, m)
            b = cand(rank(a))
            if (self%cslot(b) == 0) then
               nfresh = nfresh + 1
               fresh(nfresh) = b
            else
               wanted(self%cslot(b)) = .true.
            end if
         end do
         do sa = 1, kc
            if (self%cpix(sa) > 0 .and. .not. wanted(sa)) then
               self%cslot(self%cpix(sa)) = 0
               self%cpix(sa) = 0
            end if
         end do
         if (nfresh == 0) return
         allocate(block(n, nfresh))
         do b = 1, nfresh
            ia = (fresh(b) - 1)/np + 1
            ja = fresh(b) - (ia - 1)*np
            do a = 1, n
               block(a, b) = self%c*self%op%exact(abs(ia - self%ic(a)), abs(ja - self%jc(a)))
            end do
         end do
         call dtrsm("L", "U", "T", "N", n, nfresh, 1.0_dp, self%u, self%ld, block, n)
         b = 0
         do sa = 1, kc
            if (self%cpix(sa) /= 0) cycle
            b = b + 1
            if (b > nfresh) exit
            self%cpix(sa) = fresh(b)
            self%cslot(fresh(b)) = sa
            self%lc(1:n, sa) = block(:, b)
         end do
         call dtrsm("L", "U", "N", "N", n, nfresh, 1.0_dp, self%u, self%ld, block, n)
         do b = 1, nfresh
            self%wc(1:n, self%cslot(fresh(b))) = block(:, b)
         end do
         self%checks%cache_refills = self%checks%cache_refills + 1
         self%checks%cache_columns = self%checks%cache_columns + nfresh
      end associate
   end subroutine refill_cache
end module femcod_incremental_state
