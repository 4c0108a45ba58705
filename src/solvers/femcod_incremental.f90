!> The event-exact incremental solver (`--solver incremental`): the Appendix B model
!> condensed to the contact degrees of freedom.
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
!> to close next, kept current in O(n) each per contact and refilled with BLAS-3 solves
!> (doc/solver.md); x = M^-1 1 is updated from w, so a normal event streams no factor.
!>
!> The next event is found exactly: every pixel not in contact sits in a heap keyed by
!> a lower bound on its gap. Since F >= 0, a gap never shrinks faster than
!>     delta_max = delta + c I(0,0) sum_k max(-f_k, 0)
!> per unit load, so a pixel whose bound exceeds lambda_best * delta_max cannot close
!> before the best candidate: only pixels that can are evaluated exactly (O(n) each).
!> Releases (a contact force reaching zero) are events too. For monotonic loading the
!> history is the exact piecewise-linear solution of the contact problem.
module femcod_incremental
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gaps
   use femcod_love, only: offset_table, surface_compliance, love_influence
   use femcod_spring, only: spring_stiffness
   use femcod_lapack, only: dtrsv, dtrsm, dpotrf
   use femcod_condensed, only: gap_and_rate
   use femcod_heap, only: min_heap, heap_build, heap_push, heap_pop, heap_top_key
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_free
   use femcod_contact_result, only: contact_result, contact_options, append_step, progress_interface, &
      STOP_MAXCONT, STOP_LOADS, STOP_NO_CONTACT, record_load_states, finish_contacts, solver_state, &
      checkpoint_interface
   use femcod_sort, only: merge_sort_index
   use femcod_clock, only: wall_clock
   use femcod_memory, only: physical_memory, memory_text
   implicit none
   private
   public :: solve_incremental, scene_report

   !> Candidates whose bordering columns l = U^-T m and w = M^-1 m are kept up to date
   !> (O(n) each per new contact), and how many contacts join between refills of the
   !> cache (one pair of BLAS-3 triangular solves for the new candidates).
   integer, parameter :: CACHE_SIZE = 128, REFILL_EVERY = 64

contains

   !> What the condensed model leaves out for this deck, one line each.
   function scene_report(problem) result(lines)
      type(contact_problem), intent(in) :: problem
      character(len=160), allocatable :: lines(:)
      real(dp) :: c1, c2, s, cself
      character(len=16) :: buf
      c1 = surface_compliance(problem%young(1), problem%poisson(1), problem%pixel)
      c2 = surface_compliance(problem%young(2), problem%poisson(2), problem%pixel)
      s = 3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)
      cself = (c1 + c2)*love_influence(0, 0)
      allocate(lines(0))
      lines = [character(len=160) :: "handles, substrate and surface nodes condensed: unknowns are the contact "// &
         "forces and the approach"]
      if (c2 < c1*1.0e-3_dp) then
         write(buf, '(es9.2)') c2/c1
         lines = [character(len=160) :: lines, "upper body rigid (compliance "//trim(adjustl(buf))// &
            " of the lower's): no element of its own, kept exactly in c = c1 + c2"]
      else if (c1 < c2*1.0e-3_dp) then
         write(buf, '(es9.2)') c1/c2
         lines = [character(len=160) :: lines, "lower body rigid (compliance "//trim(adjustl(buf))// &
            " of the upper's): no element of its own, kept exactly in c = c1 + c2"]
      else if (problem%young(1) == problem%young(2) .and. problem%poisson(1) == problem%poisson(2)) then
         lines = [character(len=160) :: lines, "identical materials: one Love table, c = 2 c1"]
      else
         lines = [character(len=160) :: lines, "two elastic bodies: one Love table, c = c1 + c2"]
      end if
      write(buf, '(es9.2)') s/cself
      lines = [character(len=160) :: lines, "interface and penalty springs: an exact diagonal compliance 3/k = "// &
         trim(adjustl(buf))//" of a pixel's self-compliance"]
      if (all(problem%lower == problem%lower(1, 1))) lines = [character(len=160) :: lines, "lower surface flat"]
      if (all(problem%upper == problem%upper(1, 1))) lines = [character(len=160) :: lines, "upper surface flat"]
   end function scene_report

   !> Run the event-exact algorithm on a deck (same outputs as the legacy solver).
   !> With `checkpoint`, the state is handed over every options%checkpoint_interval
   !> seconds; with `resume`, the run continues from such a state and ends exactly as
   !> the uninterrupted run would (the caller checks that deck and options match).
   subroutine solve_incremental(problem, options, res, status, progress, checkpoint, resume)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      procedure(progress_interface), optional :: progress
      procedure(checkpoint_interface), optional :: checkpoint
      type(solver_state), intent(in), optional :: resume
      integer, allocatable :: order(:)
      ! Event search by FFT: plans and kernel (made on first use), measured costs.
      type(love_convolution) :: search_conv
      real(dp), allocatable :: field_f(:, :), field_u(:, :), disp_f(:, :), disp_u(:, :)
      integer :: last_neval
      logical :: use_fft
      ! The candidate cache: slot -> pixel, pixel -> slot, columns l and w per slot,
      ! each pixel's predicted closing load (from its last exact evaluation).
      integer, allocatable :: cpix(:), cslot(:)
      real(dp), allocatable :: lc(:, :), wc(:, :), wq(:), pred(:)
      integer :: kc, since_refill
      real(dp) :: last_checkpoint
      real(dp), allocatable :: table(:, :), g0(:), ftot(:), funit(:), u(:, :), y(:), x(:), col(:), keys(:)
      real(dp), allocatable :: lam_eval(:), gap_eval(:), loads(:)
      integer, allocatable :: ic(:), jc(:), pix(:), cstep(:), slot(:), eval_pix(:), joiners(:), items(:)
      type(min_heap) :: heap
      real(dp) :: c, s, self, total, approach, phi, delta, delta_max, beta, lam_best, lam_release, bound
      real(dp) :: tstart, t0, t1, max_load, g, rate, tie, key
      integer :: np, npix, maxc, n, step, k, p, neval, njoin, krel, q, info, ld

      call wall_clock(tstart)
      np = problem%np
      npix = np*np
      maxc = problem%maxcont
      if (options%max_contacts > 0) maxc = min(maxc, options%max_contacts)
      allocate(table(0:np - 1, 0:np - 1))
      table = offset_table(np)
      g0 = initial_gaps(problem%lower, problem%upper)
      c = surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), problem%pixel)
      s = 3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)
      self = c*table(0, 0) + s
      ld = min(maxc, 256)
      allocate(u(ld, ld))
      allocate(ic(maxc), jc(maxc), pix(maxc), cstep(maxc), ftot(maxc), funit(maxc), y(maxc), x(maxc), col(maxc))
      allocate(slot(npix), eval_pix(npix), lam_eval(npix), gap_eval(npix), joiners(npix))
      slot = 0
      last_neval = 0
      kc = min(CACHE_SIZE, npix)
      allocate(cpix(kc), cslot(npix), lc(ld, kc), wc(ld, kc), wq(maxc), pred(npix))
      cpix = 0
      cslot = 0
      pred = huge(1.0_dp)
      since_refill = 0

      ! Every pixel in the heap, keyed by its exact gap at zero load.
      allocate(items(npix))
      do p = 1, npix
         items(p) = p
      end do
      keys = g0
      ! Room for stale entries: a pixel found by the FFT search joins without leaving the
      ! heap, and a released contact is pushed back.
      call heap_build(heap, keys, items, 2*npix)
      phi = 0

      max_load = -huge(1.0_dp)
      if (allocated(options%loads)) then
         loads = options%loads
      else
         allocate(loads(0))
      end if
      if (size(loads) > 0) max_load = maxval(loads)
      allocate(res%states(size(loads)))
      res%states%load = loads
      total = 0
      approach = 0
      n = 0
      step = 0
      if (present(resume)) then
         call restore(resume)
         if (status%code /= 0) return
      else
         ! The first step: the smallest gap and every pixel tied with it (within the tie
         ! tolerance of the gaps' range; the load scale is still zero), in pixel order.
         call pop_valid(p)
         njoin = 1
         joiners(1) = p
         do while (heap%size > 0 .and. njoin < maxc)
            if (heap_top_key(heap) > g0(p) + options%tie_tolerance*(maxval(g0) - g0(p))) exit
            njoin = njoin + 1
            call heap_pop(heap, key, joiners(njoin))
         end do
         if (njoin > 1) then
            allocate(order(njoin))
            call merge_sort_index(real(joiners(1:njoin), dp), order)
            joiners(1:njoin) = joiners(order)
         end if
         do q = 1, njoin
            call add_contact(joiners(q), 1)
            if (status%code /= 0) return
         end do
      end if
      call wall_clock(last_checkpoint)

      do
         if (present(checkpoint)) call maybe_checkpoint()
         step = step + 1
         call wall_clock(t0)
         ! Unit-load solution x = M^-1 1 (kept up to date by add_contact), beta = 1'x = y'y.
         beta = sum(y(1:n)**2)
         delta = 1/beta
         funit(1:n) = x(1:n)*delta
         delta_max = delta + c*table(0, 0)*sum(max(-funit(1:n), 0.0_dp))

         ! Releases: a contact force reaching zero.
         lam_release = huge(1.0_dp)
         krel = 0
         do k = 1, n
            if (funit(k) < 0) then
               if (ftot(k)/(-funit(k)) < lam_release) then
                  lam_release = ftot(k)/(-funit(k))
                  krel = k
               end if
            end if
         end do

         ! Closing events. Either the full field by two FFT convolutions (gaps and rates
         ! of every pixel; the few within reach of the smallest closing load are then
         ! evaluated exactly), or the gap bound: pop every pixel whose lower bound allows
         ! closing first. The cheaper is chosen from the measured costs of both.
         lam_best = lam_release
         neval = 0
         use_fft = choose_fft()
         if (use_fft) then
            call fft_search()
            res%fft_steps = res%fft_steps + 1
         end if
         do
            if (use_fft) exit
            tie = options%tie_tolerance*(total + max(lam_best, 0.0_dp))
            if (lam_best < huge(1.0_dp)) then
               bound = (lam_best + tie)*delta_max
            else
               bound = huge(1.0_dp)
            end if
            if (heap%size == 0) exit
            if (heap_top_key(heap) - phi > bound) exit
            call heap_pop(heap, key, p)
            if (slot(p) /= 0) cycle
            call record_evaluation(p)
            if (neval == npix) exit
         end do
         if (.not. use_fft) last_neval = neval
         tie = options%tie_tolerance*(total + max(lam_best, 0.0_dp))
         njoin = 0
         do q = 1, neval
            if (lam_eval(q) <= lam_best + tie .and. lam_eval(q) < huge(1.0_dp)) then
               njoin = njoin + 1
               joiners(njoin) = eval_pix(q)
            else if (.not. use_fft) then
               ! Back into the heap with its exact gap as the new bound (the FFT search
               ! pops nothing: the heap's bounds stay valid as they are).
               call heap_push(heap, gap_eval(q) + phi, eval_pix(q))
            end if
         end do
         if (njoin > 1) then
            ! Tied contacts join in pixel order, so that the factor (and every result
            ! bit) does not depend on the order the heap handed them out.
            if (allocated(order)) deallocate(order)
            allocate(order(njoin))
            call merge_sort_index(real(joiners(1:njoin), dp), order)
            joiners(1:njoin) = joiners(order)
         end if
         res%missed_during_run = res%missed_during_run + count(gap_eval(1:neval) < -options%tie_tolerance*approach)

         if (lam_best >= huge(1.0_dp)) then
            ! Nothing can close and nothing is released: linear for ever.
            call record_load_states(res, huge(1.0_dp), .false., total, approach, delta, ftot(1:n), funit(1:n), &
               problem%pixel, options%hardness, ic(1:n), jc(1:n))
            res%stop_reason = STOP_NO_CONTACT
            if (size(loads) > 0) then
               if (max_load > total) call advance(max_load - total)
            end if
            call wall_clock(t1)
            call append_step(res, n, count(ftot(1:n)/problem%pixel**2 > options%hardness), total, approach, t1 - t0)
            exit
         end if
         lam_best = max(lam_best, 0.0_dp)
         call record_load_states(res, lam_best, .true., total, approach, delta, ftot(1:n), funit(1:n), &
            problem%pixel, options%hardness, ic(1:n), jc(1:n))
         call advance(lam_best)
         call wall_clock(t1)
         call append_step(res, n, count(ftot(1:n)/problem%pixel**2 > options%hardness), total, approach, t1 - t0)
         if (present(progress)) call progress(step, n, total, t1 - tstart)
         if (size(loads) > 0) then
            if (max_load <= total) then
               res%stop_reason = STOP_LOADS
               if (.not. use_fft) then
                  do q = 1, njoin
                     call heap_push(heap, phi, joiners(q))
                  end do
               end if
               exit
            end if
         end if
         if (njoin == 0 .and. krel > 0) then
            ! A release: drop contact krel and refactor (rare).
            call release_contact(krel)
            if (status%code /= 0) return
            cycle
         end if
         if (n + njoin > maxc) then
            res%stop_reason = STOP_MAXCONT
            if (.not. use_fft) then
               do q = 1, njoin
                  call heap_push(heap, phi, joiners(q))
               end do
            end if
            exit
         end if
         do q = 1, njoin
            call add_contact(joiners(q), step + 1)
            if (status%code /= 0) return
         end do
         since_refill = since_refill + njoin
         if (since_refill >= REFILL_EVERY) call refill_cache()
      end do

      call convolution_free(search_conv)
      if (options%final_check) call final_check()
      if (status%code /= 0) return
      call finish_contacts(res, ic(1:n), jc(1:n), cstep(1:n), ftot(1:n), total)
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart

   contains

      !> Evaluate a pixel exactly and record it for this step's event: its gap, the load
      !> increment that closes it, the best so far, and its predicted closing load (for
      !> the candidate cache).
      subroutine record_evaluation(pixel)
         integer, intent(in) :: pixel
         real(dp) :: gp, rp
         call evaluate(pixel, gp, rp)
         res%evaluations = res%evaluations + 1
         neval = neval + 1
         eval_pix(neval) = pixel
         gap_eval(neval) = gp
         if (gp <= 0) then
            lam_eval(neval) = 0
         else if (rp > 0) then
            lam_eval(neval) = gp/rp
         else
            lam_eval(neval) = huge(1.0_dp)
         end if
         lam_best = min(lam_best, lam_eval(neval))
         pred(pixel) = huge(1.0_dp)
         if (lam_eval(neval) < huge(1.0_dp)) pred(pixel) = total + lam_eval(neval)
      end subroutine record_evaluation

      !> Full-field search this step? options%event_search: "fft", "bound" or "auto".
      !> Auto compares the last bound search's exact evaluations (neval n table look-ups,
      !> about 2 ns each here) with two convolutions on the (2NP)^2 grid (about 5 ns per
      !> point and level each), and tries the bound search again every 16th step. The
      !> rule depends on the state only, never on timings, so runs and restarts repeat
      !> bit for bit.
      logical function choose_fft()
         real(dp) :: m2
         select case (options%event_search)
         case ("fft")
            choose_fft = n > 0
         case ("bound")
            choose_fft = .false.
         case default
            m2 = real(2*np, dp)**2
            choose_fft = n > 0 .and. mod(step, 16) /= 0 .and. &
               2.0e-9_dp*real(last_neval, dp)*n > 2*5.0e-9_dp*m2*log(m2)/log(2.0_dp)
         end select
      end function choose_fft

      !> Gaps and closing rates of every pixel from two zero-padded FFT convolutions
      !> (accumulated and unit-load forces); every pixel whose closing load lies within
      !> the FFT's error bound of the smallest (1e-9 of the displacement scale, far above
      !> the transforms' round-off) is evaluated exactly, so the event is exact.
      subroutine fft_search()
         real(dp) :: lam_min, margin, gq, rq
         real(dp), allocatable :: lam(:)
         integer :: qq, iq, jq
         if (search_conv%m == 0) then
            call convolution_setup(search_conv, table)
            allocate(field_f(np, np), field_u(np, np), disp_f(np, np), disp_u(np, np))
         end if
         field_f = 0
         field_u = 0
         do qq = 1, n
            field_f(ic(qq), jc(qq)) = ftot(qq)
            field_u(ic(qq), jc(qq)) = funit(qq)
         end do
         call convolution_apply(search_conv, field_f, disp_f)
         call convolution_apply(search_conv, field_u, disp_u)
         allocate(lam(npix))
         lam_min = lam_release
         do qq = 1, npix
            lam(qq) = huge(1.0_dp)
            if (slot(qq) /= 0) cycle
            iq = (qq - 1)/np + 1
            jq = qq - (iq - 1)*np
            gq = g0(qq) - approach + c*disp_f(iq, jq)
            rq = delta - c*disp_u(iq, jq)
            if (gq <= 0) then
               lam(qq) = 0
            else if (rq > 0) then
               lam(qq) = gq/rq
            end if
            lam_min = min(lam_min, lam(qq))
         end do
         if (lam_min >= huge(1.0_dp)) return
         margin = options%tie_tolerance*(total + lam_min) + 1.0e-9_dp*(abs(approach) + maxval(abs(g0)))/delta
         do qq = 1, npix
            if (lam(qq) > lam_min + 2*margin) cycle
            call record_evaluation(qq)
         end do
      end subroutine fft_search

      !> Hand the state to the checkpoint procedure when the interval has passed.
      subroutine maybe_checkpoint()
         type(solver_state) :: state
         real(dp) :: now
         integer :: jj, at
         if (options%checkpoint_interval < 0 .or. step == 0) return
         call wall_clock(now)
         if (now - last_checkpoint < options%checkpoint_interval) return
         state%step = step
         state%n = n
         state%total = total
         state%approach = approach
         state%phi = phi
         state%pix = pix(1:n)
         state%cstep = cstep(1:n)
         state%ftot = ftot(1:n)
         state%ld = ld
         allocate(state%factor(n*(n + 1)/2))
         at = 0
         do jj = 1, n
            state%factor(at + 1:at + jj) = u(1:jj, jj)
            at = at + jj
         end do
         state%y = y(1:n)
         state%x = x(1:n)
         state%cache_pixel = cpix
         state%cache_l = lc(1:n, :)
         state%cache_w = wc(1:n, :)
         state%predicted = pred
         state%since_refill = since_refill
         state%last_neval = last_neval
         state%heap_key = heap%key(1:heap%size)
         state%heap_item = heap%item(1:heap%size)
         state%res = res
         call checkpoint(state)
         call wall_clock(last_checkpoint)
      end subroutine maybe_checkpoint

      !> Continue from a stored state: everything the loop reads is restored bit for bit
      !> (the factor into storage of the same leading dimension), so the run goes on
      !> exactly as the uninterrupted one did.
      subroutine restore(state)
         type(solver_state), intent(in) :: state
         integer :: jj, at
         n = state%n
         if (n > maxc .or. state%ld > maxc .or. state%ld < n .or. size(state%factor) /= n*(n + 1)/2 .or. &
            size(state%cache_pixel) /= kc .or. size(state%predicted) /= npix .or. &
            size(state%heap_key) > 2*npix) then
            call set_error(status, STATUS_NUMERICAL, "incremental: the checkpoint's state does not fit this deck")
            return
         end if
         ld = state%ld
         deallocate(u, lc, wc)
         allocate(u(ld, ld), lc(ld, kc), wc(ld, kc))
         at = 0
         do jj = 1, n
            u(1:jj, jj) = state%factor(at + 1:at + jj)
            at = at + jj
         end do
         pix(1:n) = state%pix
         do jj = 1, n
            ic(jj) = (pix(jj) - 1)/np + 1
            jc(jj) = pix(jj) - (ic(jj) - 1)*np
            slot(pix(jj)) = jj
         end do
         cstep(1:n) = state%cstep
         ftot(1:n) = state%ftot
         y(1:n) = state%y
         x(1:n) = state%x
         cpix = state%cache_pixel
         cslot = 0
         do jj = 1, kc
            if (cpix(jj) > 0) cslot(cpix(jj)) = jj
         end do
         lc(1:n, :) = state%cache_l
         wc(1:n, :) = state%cache_w
         pred = state%predicted
         since_refill = state%since_refill
         last_neval = state%last_neval
         total = state%total
         approach = state%approach
         phi = state%phi
         step = state%step
         ! A valid heap rebuilt by sifting is left exactly as it was.
         call heap_build(heap, state%heap_key, state%heap_item, 2*npix)
         res = state%res
      end subroutine restore

      !> Refill the cache with the candidates predicted to close next (smallest predicted
      !> closing load from their last exact evaluation): the new ones get l = U^-T M_c
      !> and w = U^-1 l from two BLAS-3 triangular solves with all of them at once,
      !> which run at arithmetic speed where one triangular solve per contact streams
      !> the whole factor from memory.
      subroutine refill_cache()
         integer, allocatable :: cand(:), rank(:), fresh(:)
         real(dp), allocatable :: block(:, :)
         logical, allocatable :: wanted(:)
         integer :: m, nfresh, a, b, sa, ia, ja
         since_refill = 0
         m = 0
         do a = 1, npix
            if (slot(a) == 0 .and. pred(a) < huge(1.0_dp)) m = m + 1
         end do
         if (m == 0 .or. n == 0) return
         allocate(cand(m), rank(m))
         m = 0
         do a = 1, npix
            if (slot(a) == 0 .and. pred(a) < huge(1.0_dp)) then
               m = m + 1
               cand(m) = a
            end if
         end do
         call merge_sort_index(pred(cand), rank)
         allocate(wanted(kc), fresh(kc))
         wanted = .false.
         ! Keep cached candidates still among the best; evict the others.
         nfresh = 0
         do a = 1, min(kc, m)
            b = cand(rank(a))
            if (cslot(b) == 0) then
               nfresh = nfresh + 1
               fresh(nfresh) = b
            else
               wanted(cslot(b)) = .true.
            end if
         end do
         do sa = 1, kc
            if (cpix(sa) > 0 .and. .not. wanted(sa)) then
               cslot(cpix(sa)) = 0
               cpix(sa) = 0
            end if
         end do
         if (nfresh == 0) return
         allocate(block(n, nfresh))
         do b = 1, nfresh
            ia = (fresh(b) - 1)/np + 1
            ja = fresh(b) - (ia - 1)*np
            do a = 1, n
               block(a, b) = c*table(abs(ia - ic(a)), abs(ja - jc(a)))
            end do
         end do
         call dtrsm("L", "U", "T", "N", n, nfresh, 1.0_dp, u, ld, block, n)
         b = 0
         do sa = 1, kc
            if (cpix(sa) /= 0) cycle
            b = b + 1
            if (b > nfresh) exit
            cpix(sa) = fresh(b)
            cslot(fresh(b)) = sa
            lc(1:n, sa) = block(:, b)
         end do
         call dtrsm("L", "U", "N", "N", n, nfresh, 1.0_dp, u, ld, block, n)
         do b = 1, nfresh
            wc(1:n, cslot(fresh(b))) = block(:, b)
         end do
         res%cache_refills = res%cache_refills + 1
         res%cache_columns = res%cache_columns + nfresh
      end subroutine refill_cache


      !> Pop the heap until a pixel not in contact appears.
      subroutine pop_valid(pixel)
         integer, intent(out) :: pixel
         real(dp) :: kk
         do
            call heap_pop(heap, kk, pixel)
            if (slot(pixel) == 0) exit
         end do
      end subroutine pop_valid

      !> Exact gap and closing rate of a pixel not in contact.
      subroutine evaluate(pixel, gap, closing)
         integer, intent(in) :: pixel
         real(dp), intent(out) :: gap, closing
         integer :: ip, jp
         ip = (pixel - 1)/np + 1
         jp = pixel - (ip - 1)*np
         call gap_and_rate(g0(pixel), approach, delta, c, table, ip, jp, ic(1:n), jc(1:n), ftot(1:n), funit(1:n), &
            gap, closing)
      end subroutine evaluate

      !> Border the factor with a new contact (zero force): U gains a column
      !> (Uk = U^-T m, diagonal sqrt(mu - |Uk|^2)) and y = U^-T 1 one entry.
      subroutine add_contact(pixel, joined)
         integer, intent(in) :: pixel, joined
         integer :: ip, jp, kk, stat, sq, ss, ipp, jpp
         real(dp) :: d2, dq, tt
         real(dp), allocatable :: bigger(:, :)
         ip = (pixel - 1)/np + 1
         jp = pixel - (ip - 1)*np
         if (n + 1 > ld) then
            ! Grow the factor's storage by doubling (amortised O(n^2) copies), within
            ! the machine's memory (Linux would over-commit and kill the run later).
            if (physical_memory() > 0 .and. 8*int(min(2*ld, maxc), i8)**2 > physical_memory()) then
               call set_error(status, STATUS_NUMERICAL, "incremental: the factor for "// &
                  trim(i8str(int(min(2*ld, maxc), i8)))//" contacts needs "// &
                  memory_text(8*int(min(2*ld, maxc), i8)**2)//", this machine has "// &
                  memory_text(physical_memory())//"; lower MAXCONT or --max-contacts")
               return
            end if
            allocate(bigger(min(2*ld, maxc), min(2*ld, maxc)), stat=stat)
            if (stat /= 0) then
               call set_error(status, STATUS_NUMERICAL, "incremental: cannot allocate the factor for "// &
                  trim(i8str(int(min(2*ld, maxc), i8)))//" contacts ("// &
                  trim(i8str(8*int(min(2*ld, maxc), i8)**2))//" bytes)")
               return
            end if
            bigger(1:n, 1:n) = u(1:n, 1:n)
            call move_alloc(bigger, u)
            ld = size(u, 1)
            allocate(bigger(ld, kc))
            bigger(1:n, :) = lc(1:n, :)
            call move_alloc(bigger, lc)
            allocate(bigger(ld, kc))
            bigger(1:n, :) = wc(1:n, :)
            call move_alloc(bigger, wc)
         end if
         sq = cslot(pixel)
         if (sq > 0) then
            ! A cached candidate: its columns are ready.
            col(1:n) = lc(1:n, sq)
            wq(1:n) = wc(1:n, sq)
            cslot(pixel) = 0
            cpix(sq) = 0
            res%cache_hits = res%cache_hits + 1
         else
            ! l = U^-T m and w = U^-1 l = M^-1 m by two triangular solves.
            do kk = 1, n
               col(kk) = c*table(abs(ip - ic(kk)), abs(jp - jc(kk)))
            end do
            if (n > 0) call dtrsv("U", "T", "N", n, u, ld, col, 1)
            wq(1:n) = col(1:n)
            if (n > 0) call dtrsv("U", "N", "N", n, u, ld, wq, 1)
            res%cache_misses = res%cache_misses + 1
         end if
         d2 = self - sum(col(1:n)**2)
         if (.not. d2 > epsilon(1.0_dp)*self) then
            call set_error(status, STATUS_NUMERICAL, "incremental: the contact compliance lost positive definiteness")
            return
         end if
         dq = sqrt(d2)
         ! Every cached candidate p follows: l_p gains (mu_pq - l_q'l_p)/d, and
         ! w_p = M^-1 m_p becomes [w_p - w_q t; t], t = (mu_pq - l_q'l_p)/d^2 (the bordered
         ! inverse). Slots are independent: the same bits for any number of threads.
         !$omp parallel do schedule(static) private(ss, ipp, jpp, tt) if (n > 200000)
         do ss = 1, kc
            if (cpix(ss) == 0) cycle
            ipp = (cpix(ss) - 1)/np + 1
            jpp = cpix(ss) - (ipp - 1)*np
            tt = (c*table(abs(ipp - ip), abs(jpp - jp)) - dot_product(col(1:n), lc(1:n, ss)))/dq
            lc(n + 1, ss) = tt
            wc(1:n, ss) = wc(1:n, ss) - wq(1:n)*(tt/dq)
            wc(n + 1, ss) = tt/dq
         end do
         !$omp end parallel do
         u(1:n, n + 1) = col(1:n)
         u(n + 1, n + 1) = dq
         y(n + 1) = (1 - sum(col(1:n)*y(1:n)))/dq
         ! x = M^-1 1 = U^-1 y: [x - w_q eta/d; eta/d] with eta the new entry of y.
         x(1:n) = x(1:n) - wq(1:n)*(y(n + 1)/dq)
         x(n + 1) = y(n + 1)/dq
         n = n + 1
         ic(n) = ip
         jc(n) = jp
         pix(n) = pixel
         cstep(n) = joined
         ftot(n) = 0
         slot(pixel) = n
      end subroutine add_contact

      !> Remove contact k (its force is zero) and refactor the rest (LAPACK dpptrf).
      subroutine release_contact(krm)
         integer, intent(in) :: krm
         integer :: a, b
         ftot(krm) = 0
         slot(pix(krm)) = 0
         call heap_push(heap, phi, pix(krm))
         ic(krm:n - 1) = ic(krm + 1:n)
         jc(krm:n - 1) = jc(krm + 1:n)
         pix(krm:n - 1) = pix(krm + 1:n)
         cstep(krm:n - 1) = cstep(krm + 1:n)
         ftot(krm:n - 1) = ftot(krm + 1:n)
         n = n - 1
         do a = 1, n
            slot(pix(a)) = a
         end do
         do b = 1, n
            do a = 1, b
               u(a, b) = c*table(abs(ic(a) - ic(b)), abs(jc(a) - jc(b)))
            end do
            u(b, b) = u(b, b) + s
         end do
         call dpotrf("U", n, u, ld, info)
         if (info /= 0) then
            call set_error(status, STATUS_NUMERICAL, "incremental: refactorisation after a release failed")
            return
         end if
         y(1:n) = 1
         call dtrsv("U", "T", "N", n, u, ld, y, 1)
         x(1:n) = y(1:n)
         call dtrsv("U", "N", "N", n, u, ld, x, 1)
         ! The cached columns belonged to the old factor.
         do a = 1, kc
            if (cpix(a) > 0) cslot(cpix(a)) = 0
         end do
         cpix = 0
         res%releases = res%releases + 1
      end subroutine release_contact

      subroutine advance(lam)
         real(dp), intent(in) :: lam
         total = total + lam
         approach = approach + lam*delta
         ftot(1:n) = ftot(1:n) + lam*funit(1:n)
         phi = phi + lam*delta_max
      end subroutine advance

      !> Full-field check by FFT convolution: no pixel may penetrate, no force be tensile.
      subroutine final_check()
         type(love_convolution) :: conv
         real(dp), allocatable :: field(:, :), disp(:, :)
         real(dp) :: gq, worst, allowance
         integer :: qq, iq, jq
         allocate(field(np, np), disp(np, np))
         field = 0
         do qq = 1, n
            field(ic(qq), jc(qq)) = ftot(qq)
         end do
         call convolution_setup(conv, table)
         call convolution_apply(conv, field, disp)
         call convolution_free(conv)
         worst = 0
         res%missed_final_check = 0
         ! Round-off allowance: the tie tolerance of the approach plus the FFT's
         ! round-off on the height scale.
         allowance = options%tie_tolerance*max(approach, tiny(1.0_dp)) + 1.0e-12_dp*maxval(abs(g0))
         do qq = 1, npix
            if (slot(qq) /= 0) cycle
            iq = (qq - 1)/np + 1
            jq = qq - (iq - 1)*np
            gq = g0(qq) - approach + c*disp(iq, jq)
            if (gq < -allowance) then
               res%missed_final_check = res%missed_final_check + 1
            end if
            worst = min(worst, gq)
         end do
         res%max_penetration = max(0.0_dp, -worst)
         ! Drift of the event accumulation against a fresh solve of the final active set
         ! with the current factor: F = A M^-1 1 - M^-1 g0_C, A from 1'F = P (O(n^2)).
         block
            real(dp), allocatable :: w(:), fex(:)
            real(dp) :: aex
            w = g0(pix(1:n))
            call dtrsv("U", "T", "N", n, u, ld, w, 1)
            call dtrsv("U", "N", "N", n, u, ld, w, 1)
            x(1:n) = y(1:n)
            call dtrsv("U", "N", "N", n, u, ld, x, 1)
            aex = (total + sum(w))/sum(x(1:n))
            fex = aex*x(1:n) - w
            res%final_check_difference = max(abs(aex - approach)/max(abs(aex), tiny(1.0_dp)), &
               maxval(abs(fex - ftot(1:n)))/max(maxval(abs(fex)), tiny(1.0_dp)))
         end block
      end subroutine final_check
   end subroutine solve_incremental

   function i8str(v) result(str)
      integer(i8), intent(in) :: v
      character(len=24) :: str
      write(str, '(i0)') v
   end function i8str

end module femcod_incremental
