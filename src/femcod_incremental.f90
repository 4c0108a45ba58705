!> The event-exact incremental solver (`--solver incremental`): the Appendix B model
!> condensed to the contact degrees of freedom.
!>
!> With both handles and the springs eliminated, the contacts C carry forces F with
!>     M F - A 1 = -g0_C,   1'F = P,     M = c I_CC + s Id,
!> c = c1 + c2 the composite surface compliance (one Love table serves both bodies), s
!> the compliance of the springs in series at a contact (two interface springs and the
!> penalty spring, 3/k). Under a unit load increment f = M^-1 1/(1'M^-1 1) and the
!> approach rate is delta = 1/(1'M^-1 1). M = U'U is kept as a Cholesky factor in full
!> column storage that grows by doubling; a new contact borders it with one column (a
!> triangular solve, BLAS dtrsv), never a refactorisation, except when a contact is
!> released.
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
   use femcod_deck, only: deck_type
   use femcod_scene, only: initial_gaps
   use femcod_boussinesq, only: offset_table, surface_compliance, love_influence
   use femcod_spring, only: spring_stiffness
   use femcod_lapack, only: dtrsv, dpotrf
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

contains

   !> What the condensed model leaves out for this deck, one line each.
   function scene_report(deck) result(lines)
      type(deck_type), intent(in) :: deck
      character(len=160), allocatable :: lines(:)
      real(dp) :: c1, c2, s, cself
      character(len=16) :: buf
      c1 = surface_compliance(deck%young(1), deck%poisson(1), deck%pixel)
      c2 = surface_compliance(deck%young(2), deck%poisson(2), deck%pixel)
      s = 3/spring_stiffness(deck%young(3), deck%poisson(3), deck%pixel, deck%pixel)
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
      else if (deck%young(1) == deck%young(2) .and. deck%poisson(1) == deck%poisson(2)) then
         lines = [character(len=160) :: lines, "identical materials: one Love table, c = 2 c1"]
      else
         lines = [character(len=160) :: lines, "two elastic bodies: one Love table, c = c1 + c2"]
      end if
      write(buf, '(es9.2)') s/cself
      lines = [character(len=160) :: lines, "interface and penalty springs: an exact diagonal compliance 3/k = "// &
         trim(adjustl(buf))//" of a pixel's self-compliance"]
      if (all(deck%lower == deck%lower(1, 1))) lines = [character(len=160) :: lines, "lower surface flat"]
      if (all(deck%upper == deck%upper(1, 1))) lines = [character(len=160) :: lines, "upper surface flat"]
   end function scene_report

   !> Run the event-exact algorithm on a deck (same outputs as the legacy solver).
   !> With `checkpoint`, the state is handed over every options%checkpoint_interval
   !> seconds; with `resume`, the run continues from such a state and ends exactly as
   !> the uninterrupted run would (the caller checks that deck and options match).
   subroutine solve_incremental(deck, options, res, status, progress, checkpoint, resume)
      type(deck_type), intent(in) :: deck
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      procedure(progress_interface), optional :: progress
      procedure(checkpoint_interface), optional :: checkpoint
      type(solver_state), intent(in), optional :: resume
      integer, allocatable :: ops(:), order(:)
      integer :: nops
      real(dp) :: last_checkpoint
      real(dp), allocatable :: table(:, :), g0(:), ftot(:), funit(:), u(:, :), y(:), x(:), col(:), keys(:)
      real(dp), allocatable :: lam_eval(:), gap_eval(:), loads(:)
      integer, allocatable :: ic(:), jc(:), pix(:), cstep(:), slot(:), eval_pix(:), joiners(:), items(:)
      type(min_heap) :: heap
      real(dp) :: c, s, self, total, approach, phi, delta, delta_max, beta, lam_best, lam_release, bound
      real(dp) :: tstart, t0, t1, max_load, g, rate, tie, key
      integer :: np, npix, maxc, n, step, k, p, neval, njoin, krel, q, info, ld

      call wall_clock(tstart)
      np = deck%np
      npix = np*np
      maxc = deck%maxcont
      if (options%max_contacts > 0) maxc = min(maxc, options%max_contacts)
      allocate(table(0:np - 1, 0:np - 1))
      table = offset_table(np)
      g0 = initial_gaps(deck%lower, deck%upper)
      c = surface_compliance(deck%young(1), deck%poisson(1), deck%pixel) + &
         surface_compliance(deck%young(2), deck%poisson(2), deck%pixel)
      s = 3/spring_stiffness(deck%young(3), deck%poisson(3), deck%pixel, deck%pixel)
      self = c*table(0, 0) + s
      ld = min(maxc, 256)
      allocate(u(ld, ld))
      allocate(ic(maxc), jc(maxc), pix(maxc), cstep(maxc), ftot(maxc), funit(maxc), y(maxc), x(maxc), col(maxc))
      allocate(slot(npix), eval_pix(npix), lam_eval(npix), gap_eval(npix), joiners(npix))
      slot = 0

      ! Every pixel in the heap, keyed by its exact gap at zero load.
      allocate(items(npix))
      do p = 1, npix
         items(p) = p
      end do
      keys = g0
      call heap_build(heap, keys, items, npix)
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
      allocate(ops(64))
      nops = 0
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
         ! Unit-load solution from the factor: x = M^-1 1 = U^-1 y, beta = 1'x = y'y.
         x(1:n) = y(1:n)
         call dtrsv("U", "N", "N", n, u, ld, x, 1)
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

         ! Closing events: pop every pixel whose lower bound allows closing first.
         lam_best = lam_release
         neval = 0
         do
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
            call evaluate(p, g, rate)
            res%evaluations = res%evaluations + 1
            neval = neval + 1
            eval_pix(neval) = p
            gap_eval(neval) = g
            if (g <= 0) then
               lam_eval(neval) = 0
            else if (rate > 0) then
               lam_eval(neval) = g/rate
            else
               lam_eval(neval) = huge(1.0_dp)
            end if
            lam_best = min(lam_best, lam_eval(neval))
            if (neval == npix) exit
         end do
         tie = options%tie_tolerance*(total + max(lam_best, 0.0_dp))
         njoin = 0
         do q = 1, neval
            if (lam_eval(q) <= lam_best + tie .and. lam_eval(q) < huge(1.0_dp)) then
               njoin = njoin + 1
               joiners(njoin) = eval_pix(q)
            else
               ! Back into the heap with its exact gap as the new bound.
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
               deck%pixel, options%hardness, ic(1:n), jc(1:n))
            res%stop_reason = STOP_NO_CONTACT
            if (size(loads) > 0) then
               if (max_load > total) call advance(max_load - total)
            end if
            call wall_clock(t1)
            call append_step(res, n, total, approach, t1 - t0)
            exit
         end if
         lam_best = max(lam_best, 0.0_dp)
         call record_load_states(res, lam_best, .true., total, approach, delta, ftot(1:n), funit(1:n), &
            deck%pixel, options%hardness, ic(1:n), jc(1:n))
         call advance(lam_best)
         call wall_clock(t1)
         call append_step(res, n, total, approach, t1 - t0)
         if (present(progress)) call progress(step, n, total, t1 - tstart)
         if (size(loads) > 0) then
            if (max_load <= total) then
               res%stop_reason = STOP_LOADS
               do q = 1, njoin
                  call heap_push(heap, phi, joiners(q))
               end do
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
            do q = 1, njoin
               call heap_push(heap, phi, joiners(q))
            end do
            exit
         end if
         do q = 1, njoin
            call add_contact(joiners(q), step + 1)
            if (status%code /= 0) return
         end do
      end do

      if (options%final_check) call final_check()
      if (status%code /= 0) return
      call finish_contacts(res, ic(1:n), jc(1:n), cstep(1:n), ftot(1:n), total)
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart

   contains

      !> Hand the state to the checkpoint procedure when the interval has passed.
      subroutine maybe_checkpoint()
         type(solver_state) :: state
         real(dp) :: now
         if (options%checkpoint_interval < 0 .or. step == 0) return
         call wall_clock(now)
         if (now - last_checkpoint < options%checkpoint_interval) return
         state%step = step
         state%n = n
         state%total = total
         state%approach = approach
         state%operations = ops(1:nops)
         state%cstep = cstep(1:n)
         state%ftot = ftot(1:n)
         state%res = res
         call checkpoint(state)
         call wall_clock(last_checkpoint)
      end subroutine maybe_checkpoint

      !> Continue from a stored state: replay the contact operations (the same bordered
      !> updates in the same order give the same factor), restore the accumulated
      !> quantities, and key the heap by the current gaps from one FFT convolution
      !> (less a margin, so the keys stay lower bounds).
      subroutine restore(state)
         type(solver_state), intent(in) :: state
         type(love_convolution) :: conv
         real(dp), allocatable :: field(:, :), disp(:, :)
         real(dp) :: margin
         integer :: qq, iq, jq, m
         do qq = 1, size(state%operations)
            if (state%operations(qq) > 0) then
               call add_contact(state%operations(qq), 0)
            else
               call release_contact(-state%operations(qq))
            end if
            if (status%code /= 0) return
         end do
         if (n /= state%n) then
            call set_error(status, STATUS_NUMERICAL, "incremental: the checkpoint's contact list is inconsistent")
            return
         end if
         cstep(1:n) = state%cstep
         ftot(1:n) = state%ftot
         total = state%total
         approach = state%approach
         step = state%step
         res = state%res
         allocate(field(np, np), disp(np, np))
         field = 0
         do qq = 1, n
            field(ic(qq), jc(qq)) = ftot(qq)
         end do
         call convolution_setup(conv, table)
         call convolution_apply(conv, field, disp)
         call convolution_free(conv)
         margin = 1.0e-9_dp*(abs(approach) + maxval(abs(g0)))
         m = 0
         do qq = 1, npix
            if (slot(qq) /= 0) cycle
            iq = (qq - 1)/np + 1
            jq = qq - (iq - 1)*np
            m = m + 1
            keys(m) = g0(qq) - approach + c*disp(iq, jq) - margin
            items(m) = qq
         end do
         call heap_build(heap, keys(1:m), items(1:m), npix)
         phi = 0
      end subroutine restore

      !> Record a contact operation for checkpoints (+pixel joined, -k released).
      subroutine log_operation(op)
         integer, intent(in) :: op
         integer, allocatable :: longer(:)
         if (nops == size(ops)) then
            allocate(longer(2*size(ops)))
            longer(1:nops) = ops(1:nops)
            call move_alloc(longer, ops)
         end if
         nops = nops + 1
         ops(nops) = op
      end subroutine log_operation

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
         integer :: ip, jp, kk, stat
         real(dp) :: d2
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
         end if
         do kk = 1, n
            col(kk) = c*table(abs(ip - ic(kk)), abs(jp - jc(kk)))
         end do
         if (n > 0) call dtrsv("U", "T", "N", n, u, ld, col, 1)
         d2 = self - sum(col(1:n)**2)
         if (.not. d2 > epsilon(1.0_dp)*self) then
            call set_error(status, STATUS_NUMERICAL, "incremental: the contact compliance lost positive definiteness")
            return
         end if
         u(1:n, n + 1) = col(1:n)
         u(n + 1, n + 1) = sqrt(d2)
         y(n + 1) = (1 - sum(col(1:n)*y(1:n)))/u(n + 1, n + 1)
         n = n + 1
         ic(n) = ip
         jc(n) = jp
         pix(n) = pixel
         cstep(n) = joined
         ftot(n) = 0
         slot(pixel) = n
         call log_operation(pixel)
      end subroutine add_contact

      !> Remove contact k (its force is zero) and refactor the rest (LAPACK dpptrf).
      subroutine release_contact(krm)
         integer, intent(in) :: krm
         integer :: a, b
         call log_operation(-krm)
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
