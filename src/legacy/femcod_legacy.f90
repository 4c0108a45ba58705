!> The Appendix B program (`--solver legacy`): at every step the nodes and elements
!> of the current contacts are regenerated, COLHT gives the skyline, BOUSSINESQ and
!> SPRING assemble the stiffness, TRFACT factorises and solves under a unit load on
!> the top handle (bottom handle fixed), and POSTP finds the load that closes the
!> next gap. A final check over every pixel finds and corrects missed contacts.
!>
!> Equation numbering for n contacts (element by element; the fixed bottom handle is
!> eliminated): b1(k) = k (lower substrate), s1(k) = n+2k-1 and s2(k) = n+2k (lower and
!> upper surface nodes), b2(k) = 3n+k (upper substrate), top handle 4n+1. Signs: z up;
!> the load -1 nN acts on the top handle; approach = -u(top handle); the contact force
!> (compression) is k_pen (u(s1) - u(s2)).
module femcod_legacy
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_problem, only: contact_problem
   use femcod_workspace, only: workspace_type, workspace_layout, allocate_workspace, MPSURF, MPGAPS, MPDISP, &
      MPFORCE, MPSTIF, IPSORT, IPCONT, IPIADR, IPNOD1, IPNOD2, IPNOD3, IPKFIX
   use femcod_scene, only: initial_gaps
   use femcod_sort, only: merge_sort_index
   use femcod_boussinesq, only: boussinesq_flexibility, boussinesq_inverse, boussinesq_element
   use femcod_love, only: offset_table, surface_compliance
   use femcod_spring, only: spring_stiffness, spring_element
   use femcod_skyline, only: colht, diagonal_addresses, assemble_element, skyline_matvec
   use femcod_trfact, only: trfact, trfact_condition, TRFACT_FACTOR, TRFACT_SOLVE
   use femcod_postp, only: candidate_count, postp_search
   use femcod_condensed, only: solve_active_set, gap_at
   use femcod_contact_result, only: contact_result, contact_options, append_step, progress_interface, STOP_MAXCONT, &
      STOP_LOADS, STOP_NO_CONTACT, record_load_states, finish_contacts
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: solve_legacy, legacy_unit_solution

contains

   !> Run the Appendix B algorithm on a deck.
   subroutine solve_legacy(problem, options, res, status, progress)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      !> Optional progress report after every step.
      procedure(progress_interface), optional :: progress
      type(workspace_type) :: ws
      real(dp), allocatable :: table(:, :), g0(:), funit(:), ftot(:), loads(:)
      integer, allocatable :: ic(:), jc(:), joiners(:), cstep(:)
      logical, allocatable :: in_contact(:)
      real(dp) :: c1, c2, csum, kspring, delta, lambda, total, approach, tstart, t0, t1, max_load
      integer :: np, npix, maxc, n, step, ncand, njoin, nmissed, k, p, first
      real(dp) :: loss, kappa
      integer :: isurf, igaps, isort
      logical :: finished

      call wall_clock(tstart)
      np = problem%np
      npix = np*np
      maxc = problem%maxcont
      if (options%max_contacts > 0) maxc = min(maxc, options%max_contacts)
      call workspace_layout(np, maxc, ws, status)
      if (status%code /= 0) return
      call allocate_workspace(ws, status)
      if (status%code /= 0) return

      ! CREATEINPUT: heights into MPSURF, initial gaps into MPGAPS, merge sort into IPSORT.
      isurf = ws%rfirst(MPSURF)
      ws%ra(isurf:isurf + npix - 1) = reshape(transpose(problem%lower), [npix])
      ws%ra(isurf + npix:isurf + 2*npix - 1) = reshape(transpose(problem%upper), [npix])
      g0 = initial_gaps(problem%lower, problem%upper)
      igaps = ws%rfirst(MPGAPS)
      ws%ra(igaps:igaps + npix - 1) = g0
      isort = ws%ifirst(IPSORT)
      call merge_sort_index(g0, ws%ia(isort:isort + npix - 1))

      allocate(table(0:np - 1, 0:np - 1))
      table = offset_table(np)
      c1 = surface_compliance(problem%young(1), problem%poisson(1), problem%pixel)
      c2 = surface_compliance(problem%young(2), problem%poisson(2), problem%pixel)
      csum = c1 + c2
      kspring = spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)

      allocate(ic(maxc), jc(maxc), cstep(maxc), ftot(maxc), funit(maxc), in_contact(npix), joiners(npix))
      in_contact = .false.
      ftot = 0
      ! The first step: the smallest gap and every pixel tied with it (within the tie
      ! tolerance of the gaps' range; the load scale is still zero), up to MAXCONT.
      first = ws%ia(isort)
      n = 1
      call add_contact(first, 1)
      do k = 2, min(npix, maxc)
         p = ws%ia(isort + k - 1)
         if (g0(p) > g0(first) + options%tie_tolerance*(maxval(g0) - g0(first))) exit
         n = n + 1
         call add_contact(p, 1)
      end do

      max_load = -huge(1.0_dp)
      if (allocated(options%loads)) then
         loads = options%loads
         if (size(loads) > 0) max_load = maxval(loads)
      else
         allocate(loads(0))
      end if
      allocate(res%states(size(loads)))
      res%states%load = loads
      total = 0
      approach = 0
      step = 0
      finished = .false.
      do while (.not. finished)
         step = step + 1
         call wall_clock(t0)
         call legacy_unit_solution(ic(1:n), jc(1:n), table, c1, c2, kspring, ws, delta, funit(1:n), status, loss, &
            kappa)
         res%pivot_loss = max(res%pivot_loss, loss)
         res%condition = max(res%condition, kappa)
         if (status%code /= 0) return
         ncand = candidate_count(n, npix)
         call postp_search(np, ws%ia(isort:isort + npix - 1), ncand, in_contact, g0, table, csum, ic(1:n), &
            jc(1:n), ftot(1:n), approach, funit(1:n), delta, total, options%tie_tolerance, lambda, joiners, njoin, &
            nmissed, ws%ra(igaps:igaps + npix - 1))
         if (njoin == 0 .and. ncand < npix) then
            ! Nothing closes among the candidates: look at every pixel before giving up.
            call postp_search(np, ws%ia(isort:isort + npix - 1), npix, in_contact, g0, table, csum, ic(1:n), &
               jc(1:n), ftot(1:n), approach, funit(1:n), delta, total, options%tie_tolerance, lambda, joiners, &
               njoin, nmissed, ws%ra(igaps:igaps + npix - 1))
         end if
         res%missed_during_run = res%missed_during_run + nmissed
         call record_load_states(res, lambda, njoin > 0, total, approach, delta, ftot(1:n), funit(1:n), problem%pixel, &
            options%hardness, ic(1:n), jc(1:n))
         if (njoin == 0) then
            res%stop_reason = STOP_NO_CONTACT
            if (size(loads) > 0) then
               if (max_load > total) call advance(max_load - total)
            end if
            call wall_clock(t1)
            call append_step(res, n, count(ftot(1:n)/problem%pixel**2 > options%hardness), total, approach, t1 - t0)
            exit
         end if
         call advance(lambda)
         call wall_clock(t1)
         call append_step(res, n, count(ftot(1:n)/problem%pixel**2 > options%hardness), total, approach, t1 - t0)
         if (present(progress)) call progress(step, n, total, t1 - tstart)
         if (size(loads) > 0) then
            if (max_load <= total) then
               res%stop_reason = STOP_LOADS
               exit
            end if
         end if
         if (n + njoin > maxc) then
            res%stop_reason = STOP_MAXCONT
            exit
         end if
         do k = 1, njoin
            n = n + 1
            call add_contact(joiners(k), step + 1)
         end do
      end do

      ! Keep the total forces in MPFORCE, as Table B.1 does.
      ws%ra(ws%rfirst(MPFORCE):ws%rfirst(MPFORCE) + n - 1) = ftot(1:n)
      if (options%final_check) call final_check()
      if (status%code /= 0) return

      call finish_contacts(res, ic(1:n), jc(1:n), cstep(1:n), ftot(1:n), total)
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart

   contains

      subroutine add_contact(pixel, joined)
         integer, intent(in) :: pixel, joined
         ic(n) = (pixel - 1)/np + 1
         jc(n) = pixel - (ic(n) - 1)*np
         cstep(n) = joined
         ftot(n) = 0
         in_contact(pixel) = .true.
         ws%ia(ws%ifirst(IPCONT) + n - 1) = pixel
      end subroutine add_contact

      subroutine advance(lam)
         real(dp), intent(in) :: lam
         total = total + lam
         approach = approach + lam*delta
         ftot(1:n) = ftot(1:n) + lam*funit(1:n)
      end subroutine advance

      !> Appendix B's final check over all pixels: any penetration is a missed contact;
      !> it is added and the state at the final load recomputed exactly. Without missed
      !> contacts, the exact solve measures the drift of the step accumulation.
      subroutine final_check()
         real(dp), allocatable :: fex(:), g0c(:)
         real(dp) :: aex, gap, scale
         integer :: q, nextra, iq, jq
         integer, allocatable :: extra(:)
         allocate(extra(npix))
         nextra = 0
         do q = 1, npix
            if (in_contact(q)) cycle
            iq = (q - 1)/np + 1
            jq = q - (iq - 1)*np
            gap = gap_at(g0(q), approach, csum, table, iq, jq, ic(1:n), jc(1:n), ftot(1:n))
            if (gap < -options%tie_tolerance*max(approach, tiny(1.0_dp))) then
               nextra = nextra + 1
               extra(nextra) = q
            end if
         end do
         res%missed_final_check = nextra
         if (nextra > 0 .and. n + nextra <= maxc) then
            do q = 1, nextra
               n = n + 1
               call add_contact(extra(q), step)
            end do
         end if
         allocate(g0c(n))
         do q = 1, n
            g0c(q) = g0((ic(q) - 1)*np + jc(q))
         end do
         allocate(fex(n))
         call solve_active_set(ic(1:n), jc(1:n), g0c, csum, 3/kspring, table, total, fex, aex, status)
         if (status%code /= 0) return
         scale = max(maxval(abs(fex)), tiny(1.0_dp))
         res%final_check_difference = max(abs(aex - approach)/max(abs(aex), tiny(1.0_dp)), &
            maxval(abs(fex - ftot(1:n)))/scale)
         if (nextra > 0) then
            ftot(1:n) = fex
            approach = aex
            res%step_approach(res%nsteps) = aex
            res%step_contacts(res%nsteps) = n
            res%step_above_hardness(res%nsteps) = count(ftot(1:n)/problem%pixel**2 > options%hardness)
         end if
      end subroutine final_check
   end subroutine solve_legacy

   !> One legacy step: regenerate nodes and elements for the contacts (ic, jc), COLHT,
   !> assemble BOUSSINESQ (both surfaces, one flexibility) and SPRING (interface and
   !> penalty), TRFACT factor and solve under the unit load. Returns the approach per
   !> nN `delta` and the contact forces per nN `funit`.
   subroutine legacy_unit_solution(ic, jc, table, c1, c2, kspring, ws, delta, funit, status, pivot_loss, condition)
      integer, intent(in) :: ic(:), jc(:)
      real(dp), intent(in) :: table(0:, 0:), c1, c2, kspring
      type(workspace_type), intent(inout) :: ws
      real(dp), intent(out) :: delta, funit(:)
      type(status_type), intent(inout) :: status
      !> TRFACT's estimate of the digits lost (see trfact), for this factorisation.
      real(dp), intent(out), optional :: pivot_loss
      !> LAPACK-style 1-norm condition estimate of the skyline system (trfact_condition).
      real(dp), intent(out), optional :: condition
      real(dp), allocatable :: flex(:, :), kinv(:, :), element(:, :), b(:), rhs(:), r(:), kcopy(:)
      integer, allocatable :: height(:), eqs1(:), eqs2(:), iadr(:)
      integer :: n, neq, k, istif, nstif, inod
      real(dp) :: spring(2, 2)
      n = size(ic)
      neq = 4*n + 1
      ! Element connectivity, element by element (IPNOD1..3), node 1 = fixed handle.
      ! (Explicit loops: gfortran builds implied-do constructors of run-time length slowly.)
      allocate(eqs1(n + 1), eqs2(n + 1))
      do k = 1, n
         eqs1(k) = k
         eqs2(k) = 3*n + k
      end do
      eqs1(n + 1) = 0
      eqs2(n + 1) = 4*n + 1
      inod = ws%ifirst(IPNOD1)
      ws%ia(inod:inod + 2*n + 1) = [eqs1, eqs2] + 1
      inod = ws%ifirst(IPNOD2)
      do k = 1, n
         ws%ia(inod + 4*(k - 1):inod + 4*k - 1) = [k, n + 2*k - 1, n + 2*k, 3*n + k] + 1
      end do
      inod = ws%ifirst(IPNOD3)
      do k = 1, n
         ws%ia(inod + 2*(k - 1):inod + 2*k - 1) = [n + 2*k - 1, n + 2*k] + 1
      end do
      ws%ia(ws%ifirst(IPKFIX)) = 1
      ! COLHT over all elements.
      allocate(height(neq))
      height = 0
      call colht(eqs1, height)
      call colht(eqs2, height)
      do k = 1, n
         call colht([k, n + 2*k - 1], height)
         call colht([n + 2*k, 3*n + k], height)
         call colht([n + 2*k - 1, n + 2*k], height)
      end do
      allocate(iadr(neq))
      call diagonal_addresses(height, iadr)
      ws%ia(ws%ifirst(IPIADR):ws%ifirst(IPIADR) + neq - 1) = iadr
      nstif = iadr(neq)
      if (nstif > ws%real_blocks(MPSTIF)%size) then
         call set_error(status, STATUS_NUMERICAL, "legacy: the skyline outgrew MPSTIF")
         return
      end if
      istif = ws%rfirst(MPSTIF)
      associate(a => ws%ra(istif:istif + nstif - 1))
         a = 0
         ! BOUSSINESQ: one flexibility, inverted once, scaled by each surface's material.
         flex = boussinesq_flexibility(ic, jc, table)
         allocate(kinv(n, n), element(n + 1, n + 1))
         call boussinesq_inverse(flex, kinv, status)
         if (status%code /= 0) return
         call boussinesq_element(kinv, c1, element)
         call assemble_element(element, eqs1, iadr, a)
         call boussinesq_element(kinv, c2, element)
         call assemble_element(element, eqs2, iadr, a)
         ! SPRING, twice: interface springs, then penalty springs.
         spring = spring_element(kspring)
         do k = 1, n
            call assemble_element(spring, [k, n + 2*k - 1], iadr, a)
            call assemble_element(spring, [n + 2*k, 3*n + k], iadr, a)
         end do
         do k = 1, n
            call assemble_element(spring, [n + 2*k - 1, n + 2*k], iadr, a)
         end do
         ! TRFACT twice: factorise, then solve for the negative unit load on the top handle.
         ! The rigid body and the rigid springs make K stiff by five orders of magnitude
         ! across its entries; one step of iterative refinement with the assembled K
         ! (kept aside before the factorisation) restores the digits that costs.
         allocate(b(neq), rhs(neq), r(neq))
         rhs = 0
         rhs(neq) = -1
         b = rhs
         kcopy = a
         call trfact(a, iadr, b, TRFACT_FACTOR, status, pivot_loss)
         if (status%code /= 0) return
         if (present(condition)) condition = trfact_condition(a, kcopy, iadr)
         call trfact(a, iadr, b, TRFACT_SOLVE, status)
         call skyline_matvec(kcopy, iadr, b, r)
         r = rhs - r
         call trfact(a, iadr, r, TRFACT_SOLVE, status)
         b = b + r
      end associate
      ws%ra(ws%rfirst(MPDISP):ws%rfirst(MPDISP) + neq - 1) = b
      delta = -b(neq)
      do k = 1, n
         funit(k) = kspring*(b(n + 2*k - 1) - b(n + 2*k))
      end do
   end subroutine legacy_unit_solution

end module femcod_legacy
