!> The event search of the incremental solver: the smallest load increment at which a
!> pixel closes or a contact force reaches zero, and every pixel tied with it, found
!> exactly.
!>
!> Releases: contact k releases at ftot_k / (-funit_k) when funit_k < 0.
!> Closing events, by one of two searches:
!> - the gap bound: every pixel not in contact sits in a heap keyed by a lower bound on
!>   its gap. Since F >= 0, a gap never shrinks faster than delta_max per unit load
!>   (femcod_incremental_state%unit_load), so a pixel whose bound exceeds
!>   lambda_best * delta_max cannot close before the best candidate: only the pixels that
!>   can are popped and evaluated exactly (O(n) each);
!> - the full field: gaps and closing rates of every pixel from two zero-padded FFT
!>   convolutions; every pixel within the FFT's error bound of the smallest closing load
!>   is then evaluated exactly.
!> "auto" chooses the cheaper from a cost model of both that depends on the state only,
!> so runs and restarts repeat bit for bit.
module femcod_event_search
   use femcod_kinds, only: dp
   use femcod_heap, only: heap_pop, heap_push, heap_top_key
   use femcod_sort, only: merge_sort_index
   use femcod_solver_options, only: contact_options
   use femcod_incremental_state, only: incremental_state
   implicit none
   private
   public :: event_search, fft_search_pays

   !> One step's search and what it found; the FFT plans and fields are made on the
   !> first full-field search and kept for the run.
   type :: event_search
      !> Pixels evaluated exactly this step, with their gaps (nm) and closing loads (nN).
      integer :: neval = 0
      integer, allocatable :: eval_pix(:)
      real(dp), allocatable :: gap_eval(:), lam_eval(:)
      !> The smallest load increment of any event (huge: none), the smallest of the
      !> releases and the contact it releases (0: none).
      real(dp) :: lam_best = 0, lam_release = 0
      integer :: krel = 0
      !> The pixels that close at lam_best (ties within the tie tolerance), in pixel order.
      integer :: njoin = 0
      integer, allocatable :: joiners(:)
      !> The plastic cap: the smallest load increment at which a contact reaches fmax (huge:
      !> none); the contacts' pixels that cap and the capped pixels that unload (their gap
      !> opens again) at lam_best (ties within the tie tolerance); the load increment at
      !> which each capped pixel evaluated this step opens (huge: not evaluated, or closing).
      real(dp) :: lam_plastic = 0
      integer :: ncap = 0, nuncap = 0
      integer, allocatable :: cap_pix(:), uncap_pix(:)
      real(dp), allocatable :: lam_open(:)
      !> Whether this step searched the full field.
      logical :: used_fft = .false.
      real(dp), allocatable :: field_f(:, :), field_u(:, :), disp_f(:, :), disp_u(:, :)
   contains
      procedure :: next_event
   end type event_search

contains

   !> Find the next event of `state` (its unit-load solution current). The pixels the
   !> bound search evaluated but that do not join go back into the heap with their exact
   !> gaps as bounds.
   subroutine next_event(search, state, options)
      class(event_search), intent(inout) :: search
      type(incremental_state), intent(inout) :: state
      type(contact_options), intent(in) :: options
      integer, allocatable :: order(:)
      real(dp) :: tie, bound, key
      integer :: k, p, q
      if (.not. allocated(search%eval_pix)) then
         allocate(search%eval_pix(state%npix), search%gap_eval(state%npix), search%lam_eval(state%npix), &
            search%joiners(state%npix))
      end if
      associate(n => state%n, total => state%path%total)
         ! Releases: a contact force reaching zero.
         search%lam_release = huge(1.0_dp)
         search%krel = 0
         do k = 1, n
            if (state%funit(k) < 0) then
               if (state%ftot(k)/(-state%funit(k)) < search%lam_release) then
                  search%lam_release = state%ftot(k)/(-state%funit(k))
                  search%krel = k
               end if
            end if
         end do

         ! Plastic events: a contact reaching the cap, a capped pixel unloading.
         call plastic_events(search, state)

         ! Closing events.
         search%lam_best = min(search%lam_release, search%lam_plastic)
         search%neval = 0
         search%used_fft = choose_fft(state, options)
         if (search%used_fft) then
            call fft_search(search, state, options)
            state%checks%fft_steps = state%checks%fft_steps + 1
         else
            do
               tie = options%tie_tolerance*(total + max(search%lam_best, 0.0_dp))
               if (search%lam_best < huge(1.0_dp)) then
                  bound = (search%lam_best + tie)*state%delta_max
               else
                  bound = huge(1.0_dp)
               end if
               if (state%heap%size == 0) exit
               if (heap_top_key(state%heap) - state%phi > bound) exit
               call heap_pop(state%heap, key, p)
               if (state%slot(p) /= 0) cycle
               call record_evaluation(search, state, p)
               if (search%neval == state%npix) exit
            end do
            state%last_neval = search%neval
         end if

         ! Capped pixels whose gap opens before the events found so far.
         call plastic_unloading(search, state)

         ! The pixels that close at the smallest load (within the tie tolerance of the
         ! total load) join; the bound search's others go back into the heap.
         tie = options%tie_tolerance*(total + max(search%lam_best, 0.0_dp))
         search%njoin = 0
         do q = 1, search%neval
            if (search%lam_eval(q) <= search%lam_best + tie .and. search%lam_eval(q) < huge(1.0_dp)) then
               search%njoin = search%njoin + 1
               search%joiners(search%njoin) = search%eval_pix(q)
            else if (.not. search%used_fft) then
               ! The FFT search pops nothing: the heap's bounds stay valid as they are.
               call heap_push(state%heap, search%gap_eval(q) + state%phi, search%eval_pix(q))
            end if
         end do
         if (search%njoin > 1) then
            ! Tied contacts join in pixel order, so that the factor (and every result bit)
            ! does not depend on the order the heap handed them out.
            allocate(order(search%njoin))
            call merge_sort_index(real(search%joiners(1:search%njoin), dp), order)
            search%joiners(1:search%njoin) = search%joiners(order)
         end if
         state%checks%missed_during_run = state%checks%missed_during_run + &
            count(search%gap_eval(1:search%neval) < -options%tie_tolerance*state%path%approach)
         ! The plastic events of this step: every one within the tie tolerance of lam_best.
         search%ncap = 0
         search%nuncap = 0
         if (state%fmax > 0 .and. search%lam_best < huge(1.0_dp)) then
            do k = 1, n
               if (state%funit(k) > 0) then
                  if ((state%fmax - state%ftot(k))/state%funit(k) <= search%lam_best + tie) then
                     search%ncap = search%ncap + 1
                     search%cap_pix(search%ncap) = state%pix(k)
                  end if
               end if
            end do
            do q = 1, state%nplastic
               if (search%lam_open(q) <= search%lam_best + tie) then
                  search%nuncap = search%nuncap + 1
                  search%uncap_pix(search%nuncap) = state%plastic_pix(q)
               end if
            end do
         end if
      end associate
   end subroutine next_event

   !> The caps ahead (state%fmax > 0): contact k reaches fmax at the load increment
   !> (fmax - ftot_k)/funit_k when funit_k > 0; lam_plastic is the smallest.
   subroutine plastic_events(search, state)
      type(event_search), intent(inout) :: search
      type(incremental_state), intent(inout) :: state
      integer :: k
      search%lam_plastic = huge(1.0_dp)
      if (state%fmax <= 0) return
      if (.not. allocated(search%cap_pix)) allocate(search%cap_pix(state%npix), search%uncap_pix(state%npix))
      do k = 1, state%n
         if (state%funit(k) > 0) search%lam_plastic = min(search%lam_plastic, &
            max(state%fmax - state%ftot(k), 0.0_dp)/state%funit(k))
      end do
   end subroutine plastic_events

   !> Capped pixels whose gap opens again (g <= 0 rising at the rate -r > 0) before
   !> lam_best: such a pixel would leave the cap, its force falling below fmax. Each
   !> capped pixel keeps an upper bound on its gap, key + psi (psi grows by the fastest
   !> any gap can open, open_max, per unit load: femcod_incremental_state's unit_load);
   !> only a pixel whose bound could reach 0 within lam_best is evaluated exactly, and
   !> opens at g/r when r < 0. lam_best becomes the smallest opening found.
   subroutine plastic_unloading(search, state)
      type(event_search), intent(inout) :: search
      type(incremental_state), intent(inout) :: state
      real(dp) :: gap, rate, reach
      integer :: q
      if (state%fmax <= 0) return
      if (allocated(search%lam_open)) deallocate(search%lam_open)
      allocate(search%lam_open(state%nplastic))
      search%lam_open = huge(1.0_dp)
      do q = 1, state%nplastic
         reach = huge(1.0_dp)
         if (search%lam_best < huge(1.0_dp)) reach = state%plastic_key(q) + state%psi + &
            max(search%lam_best, 0.0_dp)*state%open_max
         if (reach < 0) cycle
         call state%evaluate(state%plastic_pix(q), gap, rate)
         state%checks%evaluations = state%checks%evaluations + 1
         state%plastic_key(q) = min(gap, 0.0_dp) - state%psi
         if (rate < 0) then
            search%lam_open(q) = min(gap, 0.0_dp)/rate
            search%lam_best = min(search%lam_best, search%lam_open(q))
         end if
      end do
   end subroutine plastic_unloading

   !> Evaluate a pixel exactly and record it for this step's event: its gap, the load
   !> increment that closes it, the best so far, and its predicted closing load (for the
   !> candidate cache).
   subroutine record_evaluation(search, state, pixel)
      type(event_search), intent(inout) :: search
      type(incremental_state), intent(inout) :: state
      integer, intent(in) :: pixel
      real(dp) :: gp, rp
      call state%evaluate(pixel, gp, rp)
      state%checks%evaluations = state%checks%evaluations + 1
      search%neval = search%neval + 1
      associate(q => search%neval)
         search%eval_pix(q) = pixel
         search%gap_eval(q) = gp
         if (gp <= 0) then
            search%lam_eval(q) = 0
         else if (rp > 0) then
            search%lam_eval(q) = gp/rp
         else
            search%lam_eval(q) = huge(1.0_dp)
         end if
         search%lam_best = min(search%lam_best, search%lam_eval(q))
         state%pred(pixel) = huge(1.0_dp)
         if (search%lam_eval(q) < huge(1.0_dp)) state%pred(pixel) = state%path%total + search%lam_eval(q)
      end associate
   end subroutine record_evaluation

   !> Full-field search this step? options%event_search: "fft", "bound" or "auto" (the
   !> cost model of fft_search_pays).
   logical function choose_fft(state, options)
      type(incremental_state), intent(in) :: state
      type(contact_options), intent(in) :: options
      select case (options%event_search)
      case ("fft")
         choose_fft = state%n > 0
      case ("bound")
         choose_fft = .false.
      case default
         choose_fft = fft_search_pays(state%np, state%n, state%last_neval, state%step)
      end select
   end function choose_fft

   !> The "auto" rule: the full field pays at step `step` with n contacts on an NP x NP
   !> grid when the last bound search's exact evaluations (last_neval n table look-ups,
   !> about 2 ns each here) cost more than two convolutions on the (2NP)^2 grid (about
   !> 5 ns per point and level each); every 16th step tries the bound search again. The
   !> rule depends on the state only, never on timings, so runs and restarts repeat bit
   !> for bit.
   pure logical function fft_search_pays(np, n, last_neval, step)
      integer, intent(in) :: np, n, last_neval, step
      real(dp) :: m2
      m2 = real(2*np, dp)**2
      fft_search_pays = n > 0 .and. mod(step, 16) /= 0 .and. &
         2.0e-9_dp*real(last_neval, dp)*n > 2*5.0e-9_dp*m2*log(m2)/log(2.0_dp)
   end function fft_search_pays

   !> Gaps and closing rates of every pixel from two zero-padded FFT convolutions
   !> (accumulated and unit-load forces); every pixel whose closing load lies within the
   !> FFT's error bound of the smallest (1e-9 of the displacement scale, far above the
   !> transforms' round-off) is evaluated exactly, so the event is exact.
   subroutine fft_search(search, state, options)
      type(event_search), intent(inout) :: search
      type(incremental_state), intent(inout) :: state
      type(contact_options), intent(in) :: options
      real(dp) :: lam_min, margin, gq, rq
      real(dp), allocatable :: lam(:)
      integer :: qq, iq, jq, np
      np = state%np
      if (.not. allocated(search%field_f)) &
         allocate(search%field_f(np, np), search%field_u(np, np), search%disp_f(np, np), search%disp_u(np, np))
      search%field_f = 0
      search%field_u = 0
      do qq = 1, state%n
         search%field_f(state%ic(qq), state%jc(qq)) = state%ftot(qq)
         search%field_u(state%ic(qq), state%jc(qq)) = state%funit(qq)
      end do
      call state%op%displace(search%field_f, search%disp_f)
      call state%op%displace(search%field_u, search%disp_u)
      allocate(lam(state%npix))
      lam_min = search%lam_release
      do qq = 1, state%npix
         lam(qq) = huge(1.0_dp)
         if (state%slot(qq) /= 0) cycle
         iq = (qq - 1)/np + 1
         jq = qq - (iq - 1)*np
         gq = state%g0(qq) - state%path%approach + search%disp_f(iq, jq)
         rq = state%delta - search%disp_u(iq, jq)
         if (gq <= 0) then
            lam(qq) = 0
         else if (rq > 0) then
            lam(qq) = gq/rq
         end if
         lam_min = min(lam_min, lam(qq))
      end do
      if (lam_min >= huge(1.0_dp)) return
      margin = options%tie_tolerance*(state%path%total + lam_min) + &
         1.0e-9_dp*(abs(state%path%approach) + maxval(abs(state%g0)))/state%delta
      do qq = 1, state%npix
         if (lam(qq) > lam_min + 2*margin) cycle
         call record_evaluation(search, state, qq)
      end do
   end subroutine fft_search
end module femcod_event_search
