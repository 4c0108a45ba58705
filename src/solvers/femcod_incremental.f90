!> The event-exact incremental solver (`--solver incremental`): the Appendix B model
!> condensed to the contact degrees of freedom (the state and its operations:
!> femcod_incremental_state; the event search: femcod_event_search). Each step:
!>   1. the solution under a unit load increment (forces per nN, approach rate);
!>   2. the next event: the smallest load increment at which a pixel closes or a
!>      contact force reaches zero, with every pixel tied with it;
!>   3. the end of the step on the load path (requested loads inside it, the advance,
!>      the history row; femcod_event_path, shared with the legacy solver);
!>   4. the event itself: a release refactors, joining pixels border the factor.
!> For monotonic loading the history is the exact piecewise-linear solution of the
!> contact problem; a full-field check by FFT convolution closes the run.
!> With the plastic cap (--plastic) a step may also end where a contact reaches
!> fmax = H d^2 (it leaves the elastic set, keeping fmax: femcod_incremental_state's
!> cap_contact) or where a capped pixel's gap opens again (it rejoins).
module femcod_incremental
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_INTERRUPTED, STATUS_NUMERICAL
   use femcod_strings, only: int_str, sig_str
   use femcod_problem, only: contact_problem
   use femcod_lapack, only: dtrsv
   use femcod_heap, only: heap_pop, heap_push, heap_top_key
   use femcod_sort, only: merge_sort_index
   use femcod_contact_result, only: contact_result, STOP_MAXCONT, STOP_NO_CONTACT, finish_contacts
   use femcod_solver_options, only: contact_options
   use femcod_observer, only: solver_observer
   use femcod_event_path, only: first_touch_limit, NO_EVENT
   use femcod_incremental_state, only: incremental_state, REFILL_EVERY, factor_peak_bytes
   use femcod_elastic_operator, only: grid_operator_free
   use femcod_memory, only: memory_text, usable_text
   use femcod_event_search, only: event_search
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: solve_incremental

contains

   !> Run the event-exact algorithm on a problem (the same history as the legacy
   !> solver). The observer hears of every step, and gets the complete state every
   !> options%checkpoint_interval seconds; with `resume` (a state stored that way and
   !> read back for this problem and these options) the run continues from it and ends
   !> exactly as the uninterrupted run would.
   subroutine solve_incremental(problem, options, res, status, observer, resume)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(incremental_state), intent(inout), optional :: resume
      type(incremental_state) :: fresh
      real(dp) :: tstart
      call wall_clock(tstart)
      if (present(resume)) then
         ! The budget is this run's, not the stored run's.
         resume%memory_available = options%memory_available
         call event_loop(resume, problem, options, res, status, observer, tstart)
      else
         call check_memory(status)
         if (status%code /= 0) return
         call fresh%init(problem, options)
         call first_contacts(fresh, options, status, observer, tstart)
         if (status%code /= 0) return
         call event_loop(fresh, problem, options, res, status, observer, tstart)
      end if
   contains
      !> MAXCONT (or --max-contacts) bounds the run: a path may go there, with loads too
      !> (a flat scene's first touch alone may bring every pixel), so a factor of that many
      !> contacts that cannot fit is refused before the run starts rather than after hours
      !> of steps (the factor's growth checks each doubling too: add_contact).
      subroutine check_memory(st)
         type(status_type), intent(inout) :: st
         integer(i8) :: need, may
         integer :: target
         target = problem%maxcont
         if (options%max_contacts > 0) target = min(options%max_contacts, problem%np**2)
         need = factor_peak_bytes(target, problem%np**2)
         may = options%memory_available
         if (may > 0 .and. need > may) call set_error(st, STATUS_NUMERICAL, "incremental: "//int_str(target)// &
            " contacts (MAXCONT or --max-contacts) need "//memory_text(need)//" for the factor of their "// &
            "compliance (8 bytes x "//int_str(target)//"^2, and the one it grows from), this run may use "// &
            usable_text(may)//"; lower MAXCONT or --max-contacts (the run still stops at its loads), or use "// &
            "--solver cg")
      end subroutine check_memory
   end subroutine solve_incremental

   !> Steps from `state` until the path stops, then the final check and the result.
   subroutine event_loop(state, problem, options, res, status, observer, tstart)
      type(incremental_state), intent(inout) :: state
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), intent(in) :: tstart
      type(event_search) :: search
      real(dp) :: t0, t1, last_checkpoint, lam, total_before, tie
      integer :: q, k, reason, release_pixel
      logical, allocatable :: reached_before(:)

      call wall_clock(last_checkpoint)

      do
         if (observer%stop_requested()) then
            ! Stop between two steps: the state is complete, so a checkpoint continues it.
            if (options%checkpoint_interval >= 0) call observer%checkpoint(problem, options, state)
            call set_error(status, STATUS_INTERRUPTED, "stopped at step "//int_str(state%step)//" ("// &
               int_str(state%n)//" contacts, load "//sig_str(state%path%total, 6)//" nN)")
            return
         end if
         if (options%checkpoint_interval >= 0 .and. state%step > 0) then
            call wall_clock(t1)
            if (t1 - last_checkpoint >= options%checkpoint_interval) then
               call observer%checkpoint(problem, options, state)
               call wall_clock(last_checkpoint)
            end if
         end if
         state%step = state%step + 1
         call wall_clock(t0)
         call state%unit_load()
         call search%next_event(state, options)

         lam = NO_EVENT
         if (search%lam_best < huge(1.0_dp)) lam = max(search%lam_best, 0.0_dp)
         total_before = state%path%total
         reached_before = state%res%states%reached
         associate(n => state%n)
            if (state%nplastic == 0) then
               reason = state%path%close_step(state%res, lam, state%delta, state%ftot(1:n), state%funit(1:n), &
                  state%ic(1:n), state%jc(1:n), t0)
            else
               reason = close_with_plastic()
            end if
            if (state%fmax > 0) then
               state%res%step_plastic = [state%res%step_plastic, state%nplastic]
               where (state%res%states%reached .and. .not. reached_before) state%res%states%n_plastic = state%nplastic
            end if
            if (reason /= STOP_NO_CONTACT) then
               state%phi = state%phi + lam*state%delta_max
               state%psi = state%psi + lam*state%open_max
               call wall_clock(t1)
               call observer%progress(state%step, n, state%path%total, t1 - tstart)
            end if
         end associate
         if (reason /= 0) then
            state%res%stop_reason = reason
            if (reason /= STOP_NO_CONTACT) call return_joiners()
            exit
         end if
         ! Plastic events: contacts reaching the cap leave the elastic set, capped pixels
         ! whose gaps open rejoin it.
         release_pixel = 0
         if (search%krel > 0) release_pixel = state%pix(search%krel)
         do q = 1, search%ncap
            k = state%slot(search%cap_pix(q))
            if (k <= 0) cycle
            state%ftot(k) = state%fmax
            call state%cap_contact(k, state%step, status)
            if (status%code /= 0) return
         end do
         do q = 1, search%nuncap
            call state%uncap_pixel(search%uncap_pix(q), state%step + 1, status)
            if (status%code /= 0) return
         end do
         tie = options%tie_tolerance*(total_before + lam)
         if (search%njoin == 0 .and. release_pixel > 0 .and. search%lam_release <= search%lam_best + tie) then
            ! A release: drop the contact and refactor (rare).
            call state%release_contact(state%slot(release_pixel), status)
            if (status%code /= 0) return
            cycle
         end if
         if (state%n == 0 .and. search%njoin == 0) then
            ! Every contact capped: the load cannot grow until the next pixel touches.
            call touch_again(state, options, status)
            if (status%code /= 0) return
            if (state%n == 0) then
               ! No pixel joined: either none is left, or MAXCONT leaves no room for it.
               state%res%stop_reason = STOP_NO_CONTACT
               if (state%nplastic < state%npix .and. .not. state%path%room_for(state%nplastic, 1)) &
                  state%res%stop_reason = STOP_MAXCONT
               exit
            end if
            cycle
         end if
         if (.not. state%path%room_for(state%n + state%nplastic, search%njoin)) then
            state%res%stop_reason = STOP_MAXCONT
            call return_joiners()
            exit
         end if
         do q = 1, search%njoin
            call state%add_contact(search%joiners(q), state%step + 1, status)
            if (status%code /= 0) return
         end do
         state%since_refill = state%since_refill + search%njoin
         if (state%since_refill >= REFILL_EVERY) call state%refill_cache()
      end do

      call finish_events(state, options, res, tstart)
      call grid_operator_free(state%op)

   contains

      !> close_step with the capped pixels beside the elastic contacts (forces fmax, no
      !> rate), so that the history and the load states count and carry them.
      integer function close_with_plastic() result(why)
         real(dp), allocatable :: fall(:), uall(:)
         integer, allocatable :: iall(:), jall(:)
         associate(n => state%n, npl => state%nplastic, pp => state%plastic_pix)
            fall = [state%ftot(1:n), spread(state%fmax, 1, npl)]
            uall = [state%funit(1:n), spread(0.0_dp, 1, npl)]
            iall = [state%ic(1:n), (pp(1:npl) - 1)/state%np + 1]
            jall = [state%jc(1:n), pp(1:npl) - ((pp(1:npl) - 1)/state%np)*state%np]
            why = state%path%close_step(state%res, lam, state%delta, fall, uall, iall, jall, t0)
            state%ftot(1:n) = fall(1:n)
         end associate
      end function close_with_plastic

      !> The joiners of a step that ends the run go back into the heap (the bound search
      !> popped them), so that the heap stays the set of pixels not in contact.
      subroutine return_joiners()
         integer :: k
         if (search%used_fft) return
         do k = 1, search%njoin
            call heap_push(state%heap, state%phi, search%joiners(k))
         end do
      end subroutine return_joiners
   end subroutine event_loop

   !> The end of the event loop: the final check (options%final_check), the contact list
   !> (the capped pixels after the elastic contacts, at the cap's force), the plastic
   !> displacements, and the result with its wall time since `tstart`.
   subroutine finish_events(state, options, res, tstart)
      type(incremental_state), intent(inout) :: state
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      real(dp), intent(in) :: tstart
      real(dp) :: t1
      if (options%final_check) call final_check(state, options)
      associate(n => state%n, npl => state%nplastic)
         if (npl == 0) then
            call finish_contacts(state%res, state%ic(1:n), state%jc(1:n), state%cstep(1:n), state%ftot(1:n), &
               state%path%total)
         else
            call finish_contacts(state%res, [state%ic(1:n), (state%plastic_pix(1:npl) - 1)/state%np + 1], &
               [state%jc(1:n), state%plastic_pix(1:npl) - ((state%plastic_pix(1:npl) - 1)/state%np)*state%np], &
               [state%cstep(1:n), state%plastic_step(1:npl)], [state%ftot(1:n), spread(state%fmax, 1, npl)], &
               state%path%total)
         end if
      end associate
      if (state%fmax > 0) call plastic_displacements(state)
      res = state%res
      allocate(res%diagnostics, source=state%checks)
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart
   end subroutine finish_events

   !> The first step's contacts: the smallest gap and every pixel tied with it (within
   !> the tie tolerance of the gaps' range; the load scale is still zero), in pixel order.
   subroutine first_contacts(state, options, status, observer, tstart)
      type(incremental_state), intent(inout) :: state
      type(contact_options), intent(in) :: options
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      real(dp), intent(in) :: tstart
      real(dp) :: now
      integer, allocatable :: joiners(:), order(:)
      real(dp) :: key, limit
      integer :: p, njoin, q
      allocate(joiners(state%npix))
      call heap_pop(state%heap, key, p)
      njoin = 1
      joiners(1) = p
      limit = first_touch_limit(state%g0, state%g0(p), options%tie_tolerance)
      do while (state%heap%size > 0 .and. njoin < state%maxc)
         if (heap_top_key(state%heap) > limit) exit
         njoin = njoin + 1
         call heap_pop(state%heap, key, joiners(njoin))
      end do
      if (njoin > 1) then
         allocate(order(njoin))
         call merge_sort_index(real(joiners(1:njoin), dp), order)
         joiners(1:njoin) = joiners(order)
      end if
      do q = 1, njoin
         call state%add_contact(joiners(q), 1, status)
         if (status%code /= 0) return
         if (mod(q, 1024) == 0) then
            ! A tie of many pixels (a flat punch) borders the factor O(n^2) each: report.
            call wall_clock(now)
            call observer%progress(0, q, 0.0_dp, now - tstart)
            if (observer%stop_requested()) then
               call set_error(status, STATUS_INTERRUPTED, "stopped in the first step, after "//int_str(q)//" of "// &
                  int_str(njoin)//" tied contacts")
               return
            end if
         end if
      end do
   end subroutine first_contacts

   !> Full-field check by FFT convolution: no pixel may penetrate, no force be tensile;
   !> and the drift of the event accumulation against a fresh solve of the final active
   !> set with the current factor.
   subroutine final_check(state, options)
      type(incremental_state), intent(inout) :: state
      type(contact_options), intent(in) :: options
      real(dp), allocatable :: field(:, :), disp(:, :), w(:), fex(:)
      real(dp) :: gq, worst, allowance, aex
      integer :: qq, iq, jq, np
      np = state%np
      allocate(field(np, np), disp(np, np))
      field = 0
      do qq = 1, state%n
         field(state%ic(qq), state%jc(qq)) = state%ftot(qq)
      end do
      call state%op%displace(field, disp)
      worst = 0
      state%checks%missed_final_check = 0
      ! Round-off allowance: the tie tolerance of the approach plus the FFT's round-off
      ! on the height scale.
      allowance = options%tie_tolerance*max(state%path%approach, tiny(1.0_dp)) + 1.0e-12_dp*maxval(abs(state%g0))
      do qq = 1, state%npix
         if (state%slot(qq) /= 0) cycle
         iq = (qq - 1)/np + 1
         jq = qq - (iq - 1)*np
         gq = state%g0(qq) - state%path%approach + disp(iq, jq)
         if (gq < -allowance) state%checks%missed_final_check = state%checks%missed_final_check + 1
         worst = min(worst, gq)
      end do
      state%checks%max_penetration = max(0.0_dp, -worst)
      ! F = A M^-1 1 - M^-1 g0_C, A from 1'F = P (O(n^2)); with every contact capped there
      ! is no elastic set to re-solve, and nothing that could differ.
      state%checks%final_check_difference = 0
      if (state%n == 0) return
      associate(n => state%n, u => state%u, ld => state%ld)
         w = state%g0(state%pix(1:n))
         call dtrsv("U", "T", "N", n, u, ld, w, 1)
         call dtrsv("U", "N", "N", n, u, ld, w, 1)
         state%x(1:n) = state%y(1:n)
         call dtrsv("U", "N", "N", n, u, ld, state%x, 1)
         aex = (state%path%total - state%nplastic*state%fmax + sum(w))/sum(state%x(1:n))
         fex = aex*state%x(1:n) - w
         state%checks%final_check_difference = max(abs(aex - state%path%approach)/max(abs(aex), tiny(1.0_dp)), &
            maxval(abs(fex - state%ftot(1:n)))/max(maxval(abs(fex)), tiny(1.0_dp)))
      end associate
   end subroutine final_check

   !> Every contact is capped and the load cannot grow until another pixel touches: the
   !> approach moves on at constant load to the smallest gap of the free pixels (exact:
   !> with no elastic contact a gap is g0 - approach), and that pixel and every pixel
   !> tied with it join. The heap's bounds move with the approach.
   subroutine touch_again(state, options, status)
      type(incremental_state), intent(inout) :: state
      type(contact_options), intent(in) :: options
      type(status_type), intent(inout) :: status
      real(dp) :: lowest, limit, shift
      integer :: p
      lowest = huge(1.0_dp)
      do p = 1, state%npix
         if (state%slot(p) == 0) lowest = min(lowest, state%g0(p))
      end do
      if (lowest >= huge(1.0_dp)) return
      shift = max(lowest - state%path%approach, 0.0_dp)
      state%path%approach = state%path%approach + shift
      state%phi = state%phi + shift
      limit = lowest + options%tie_tolerance*max(abs(lowest), maxval(abs(state%g0)))
      do p = 1, state%npix
         if (state%slot(p) /= 0 .or. state%g0(p) > limit) cycle
         if (.not. state%path%room_for(state%n + state%nplastic, 1)) exit
         call state%add_contact(p, state%step + 1, status)
         if (status%code /= 0) return
      end do
   end subroutine touch_again

   !> The plastic displacement of every reached load state: at its capped pixels (force
   !> fmax), minus the gap g0 - approach + c sum_k I(p - k) F_k + s fmax over all its
   !> contacts (the deck's gaps; the springs' compression is elastic), summed directly;
   !> their sum times d^2 is the plastic volume.
   subroutine plastic_displacements(state)
      type(incremental_state), intent(inout) :: state
      integer :: s, k, m, np
      real(dp) :: gap, d2
      np = state%np
      d2 = state%fmax/state%path%hardness
      do s = 1, size(state%res%states)
         associate(st => state%res%states(s))
            if (.not. st%reached) cycle
            allocate(st%plastic(np, np))
            st%plastic = 0
            st%n_plastic = count(st%force >= state%fmax)
            do k = 1, size(st%force)
               if (st%force(k) < state%fmax) cycle
               gap = state%g0_deck((st%i(k) - 1)*np + st%j(k)) - st%approach + state%s*st%force(k)
               do m = 1, size(st%force)
                  gap = gap + state%c*state%op%exact(abs(st%i(k) - st%i(m)), abs(st%j(k) - st%j(m)))*st%force(m)
               end do
               st%plastic(st%i(k), st%j(k)) = max(-gap, 0.0_dp)
            end do
            st%plastic_volume = sum(st%plastic)*d2
         end associate
      end do
   end subroutine plastic_displacements
end module femcod_incremental
