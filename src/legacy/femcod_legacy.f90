!> The Appendix B program (`--solver legacy`), computing in its two work arrays as the
!> thesis' program does: every block of Tables B.1 and B.2 is written and read through
!> its memory pointer (legacy/femcod_workspace, doc/workspace.md).
!>
!> CREATEINPUT puts the heights into MPSURF, the initial gaps into MPGAPS, their merge
!> sort into IPSORT and the material numbers of the three element types into IPMAT,
!> IPMAT2, IPMAT3. At every step the nodes of the current contacts (IPCONT) are
!> regenerated (coordinates in MPCORD, the fixed bottom handle in IPKFIX, connectivity
!> in IPNOD1-3), COLHT gives the skyline (IPIADR), BOUSSINESQ and SPRING assemble the
!> stiffness (MPSTIF), TRFACT factorises and solves under the unit load of MPFEXT on the
!> top handle (MPDISP), the contact forces per unit load go to MPWORK, and POSTP finds
!> the load that closes the next gap among the candidates (IPSITU marks those in
!> contact); the total forces accumulate in MPFORCE. A final check over every pixel
!> puts the displacement of every pixel at the last contact into MPDISP2, finds and
!> corrects missed contacts.
!>
!> Node numbering for n contacts: node 1 the bottom handle (fixed), then lower substrate
!> b1(k) = 1+k, lower and upper surface s1(k) = 1+n+2k-1 and s2(k) = 1+n+2k, upper
!> substrate b2(k) = 1+3n+k, top handle 4n+2. Equations follow the nodes, the fixed one
!> eliminated. Signs: z up; the load -1 nN acts on the top handle; approach = -u(top
!> handle); the contact force (compression) is k_pen (u(s1) - u(s2)).
!>
!> Beyond Appendix B, and outside the work arrays: one step of iterative refinement with
!> a copy of the assembled skyline (the rigid body costs TRFACT digits), its condition
!> estimate, and the step at which each contact joined (for the results).
module femcod_legacy
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED
   use femcod_strings, only: int_str
   use femcod_problem, only: contact_problem
   use femcod_workspace, only: workspace_type, workspace_layout, allocate_workspace, MPSURF, MPGAPS, MPCORD, &
      MPFEXT, MPDISP, MPDISP2, MPFORCE, MPWORK, MPSTIF, IPSORT, IPKFIX, IPMAT, IPMAT2, IPMAT3, IPIADR, IPNOD1, &
      IPNOD2, IPNOD3, IPCONT, IPSITU
   use femcod_scene, only: initial_gaps
   use femcod_sort, only: merge_sort_index
   use femcod_love, only: offset_table, surface_compliance
   use femcod_boussinesq, only: boussinesq_flexibility, boussinesq_inverse, boussinesq_element
   use femcod_spring, only: spring_stiffness, spring_element
   use femcod_skyline, only: colht, diagonal_addresses, assemble_element, skyline_matvec
   use femcod_trfact, only: trfact, trfact_condition, TRFACT_FACTOR, TRFACT_SOLVE
   use femcod_postp, only: candidate_count, postp_search, in_contact_at
   use femcod_condensed, only: solve_active_set, gap_at
   use femcod_contact_result, only: contact_result, STOP_MAXCONT, STOP_NO_CONTACT, STOP_INTERRUPTED, finish_contacts, &
      legacy_diagnostics
   use femcod_solver_options, only: contact_options
   use femcod_observer, only: solver_observer
   use femcod_event_path, only: load_path, first_touch_limit, NO_EVENT
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: solve_legacy, legacy_unit_solution, legacy_materials, read_materials, MATERIAL_NUMBERS

   !> Material numbers (1 lower surface, 2 upper surface, 3 contact elements) that
   !> CREATEINPUT stores for the element types: IPMAT (the two Boussinesq elements),
   !> IPMAT2 (the interface springs of the lower and upper surface), IPMAT3 (the penalty
   !> springs; both words name the contact material).
   integer, parameter :: MATERIAL_NUMBERS(2, 3) = reshape([1, 2, 3, 3, 3, 3], [2, 3])

   !> The element constants of one run, from the materials IPMAT* name: the surface
   !> compliance factors of the two Boussinesq elements (nm/nN) and the stiffness of the
   !> lower and upper interface springs and of the penalty spring (nN/nm).
   type :: legacy_materials
      real(dp) :: compliance(2) = 0, interface(2) = 0, penalty = 0
   end type legacy_materials

   !> Where one run's arrays start in the work arrays (Appendix B's memory pointers): the
   !> surfaces (MPSURF), gaps (MPGAPS), their order (IPSORT), the candidates' flags
   !> (IPSITU), the contacts (IPCONT), the contact forces (MPFORCE) and the unit
   !> solution (MPWORK).
   type :: legacy_pointers
      integer :: surf = 0, gaps = 0, sort = 0, situ = 0, cont = 0, force = 0, work = 0
   end type legacy_pointers

contains

   !> Run the Appendix B algorithm on a problem.
   subroutine solve_legacy(problem, options, res, status, observer)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      !> Told of every step (progress).
      class(solver_observer), intent(inout) :: observer
      type(workspace_type) :: ws
      type(load_path) :: path
      type(legacy_materials) :: mat
      real(dp), allocatable :: table(:, :)
      type(legacy_pointers) :: at
      integer, allocatable :: joiners(:), joiner_ranks(:), cstep(:), ic(:), jc(:)
      real(dp) :: csum, delta, lambda, tstart, t0, t1, loss, kappa, limit
      integer :: np, npix, n, step, ncand, njoin, nmissed, k, reason
      !> What the run found and how well its systems were conditioned (res%diagnostics).
      type(legacy_diagnostics) :: checks

      call wall_clock(tstart)
      np = problem%np
      npix = np*np
      call path%start(problem, options, res)
      call workspace_layout(np, path%max_contacts, ws, status)
      if (status%code /= 0) return
      call allocate_workspace(ws, status, options%memory_available)
      if (status%code /= 0) return
      at = legacy_pointers(surf=ws%rfirst(MPSURF), gaps=ws%rfirst(MPGAPS), sort=ws%ifirst(IPSORT), &
         situ=ws%ifirst(IPSITU), cont=ws%ifirst(IPCONT), force=ws%rfirst(MPFORCE), work=ws%rfirst(MPWORK))

      ! CREATEINPUT: heights into MPSURF, the initial gaps computed from them into
      ! MPGAPS, their merge sort into IPSORT, the element types' materials into IPMAT*.
      ws%ra(at%surf:at%surf + npix - 1) = reshape(transpose(problem%lower), [npix])
      ws%ra(at%surf + npix:at%surf + 2*npix - 1) = reshape(transpose(problem%upper), [npix])
      ws%ra(at%gaps:at%gaps + npix - 1) = initial_gaps(surface_of(ws, at, np, 1), surface_of(ws, at, np, 2))
      call merge_sort_index(ws%ra(at%gaps:at%gaps + npix - 1), ws%ia(at%sort:at%sort + npix - 1))
      ws%ia(ws%ifirst(IPMAT):ws%ilast(IPMAT)) = MATERIAL_NUMBERS(:, 1)
      ws%ia(ws%ifirst(IPMAT2):ws%ilast(IPMAT2)) = MATERIAL_NUMBERS(:, 2)
      ws%ia(ws%ifirst(IPMAT3):ws%ilast(IPMAT3)) = MATERIAL_NUMBERS(:, 3)
      mat = read_materials(ws, problem)
      csum = mat%compliance(1) + mat%compliance(2)

      allocate(table(0:np - 1, 0:np - 1))
      table = offset_table(np)
      allocate(cstep(path%max_contacts), joiners(npix), joiner_ranks(npix))

      n = 0
      associate(g0 => ws%ra(at%gaps:at%gaps + npix - 1), order => ws%ia(at%sort:at%sort + npix - 1), &
         situ => ws%ia(at%situ:ws%ilast(IPSITU)))
         ! The first step: the smallest gap and every pixel tied with it, up to MAXCONT.
         limit = first_touch_limit(g0, g0(order(1)), options%tie_tolerance)
         do k = 1, min(npix, path%max_contacts)
            if (k > 1 .and. g0(order(k)) > limit) exit
            call add_contact(ws, at, n, cstep, order(k), k, 1)
         end do

         step = 0
         do
            if (observer%stop_requested()) then
               ! The states reached so far are kept (a partial run, written by the caller).
               call set_error(status, STATUS_INTERRUPTED, "stopped at step "//int_str(step)//" ("//int_str(n)// &
                  " contacts)")
               res%stop_reason = STOP_INTERRUPTED
               exit
            end if
            step = step + 1
            call wall_clock(t0)
            call legacy_unit_solution(ws, n, table, mat, problem%pixel, delta, status, loss, kappa)
            checks%pivot_loss = max(checks%pivot_loss, loss)
            checks%condition = max(checks%condition, kappa)
            if (status%code /= 0) return
            ncand = candidate_count(n, npix)
            call postp_search(np, order, ncand, situ, ws%ia(at%cont:at%cont + n - 1), g0, table, csum, &
               ws%ra(at%force:at%force + n - 1), path%approach, ws%ra(at%work:at%work + n - 1), delta, path%total, &
               options%tie_tolerance, lambda, joiners, joiner_ranks, njoin, nmissed)
            if (njoin == 0 .and. ncand < npix) then
               ! Nothing closes among the candidates: look at every pixel before giving up.
               call postp_search(np, order, npix, situ, ws%ia(at%cont:at%cont + n - 1), g0, table, csum, &
                  ws%ra(at%force:at%force + n - 1), path%approach, ws%ra(at%work:at%work + n - 1), delta, path%total, &
                  options%tie_tolerance, lambda, joiners, joiner_ranks, njoin, nmissed)
            end if
            checks%missed_during_run = checks%missed_during_run + nmissed
            if (njoin == 0) lambda = NO_EVENT
            call contact_rows_cols(ws, n, ic, jc)
            reason = path%close_step(res, lambda, delta, ws%ra(at%force:at%force + n - 1), ws%ra(at%work:at%work + n - 1), &
               ic, jc, t0)
            if (reason /= STOP_NO_CONTACT) then
               call wall_clock(t1)
               call observer%progress(step, n, path%total, t1 - tstart)
            end if
            if (reason /= 0) then
               res%stop_reason = reason
               exit
            end if
            if (.not. path%room_for(n, njoin)) then
               res%stop_reason = STOP_MAXCONT
               exit
            end if
            do k = 1, njoin
               call add_contact(ws, at, n, cstep, joiners(k), joiner_ranks(k), step + 1)
            end do
         end do

         if (options%final_check .and. status%code == 0) call final_check(ws, at, n, cstep, step, table, csum, mat, &
            problem, options, path, res, checks, status)
         allocate(res%diagnostics, source=checks)
         if (status%code /= 0 .and. status%code /= STATUS_INTERRUPTED) return
         call contact_rows_cols(ws, n, ic, jc)
         call finish_contacts(res, ic, jc, cstep(1:n), ws%ra(at%force:at%force + n - 1), path%total)
      end associate
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart
   end subroutine solve_legacy

   !> Surface `which` (1 lower, 2 upper) from MPSURF, row i column j as in the deck.
   function surface_of(ws, at, np, which) result(z)
      type(workspace_type), intent(in) :: ws
      type(legacy_pointers), intent(in) :: at
      integer, intent(in) :: np, which
      real(dp) :: z(np, np)
      z = transpose(reshape(ws%ra(at%surf + (which - 1)*np*np:at%surf + which*np*np - 1), [np, np]))
   end function surface_of

   !> Contact n+1 at `pixel` (gap rank `rank`), joined at step `joined`, with no force.
   subroutine add_contact(ws, at, n, cstep, pixel, rank, joined)
      type(workspace_type), intent(inout) :: ws
      type(legacy_pointers), intent(in) :: at
      integer, intent(inout) :: n, cstep(:)
      integer, intent(in) :: pixel, rank, joined
      n = n + 1
      ws%ia(at%cont + n - 1) = pixel
      ws%ra(at%force + n - 1) = 0
      if (rank <= ws%int_blocks(IPSITU)%size) ws%ia(at%situ + rank - 1) = 1
      cstep(n) = joined
   end subroutine add_contact

   !> Appendix B's final check over all pixels: the displacement of every pixel at the
   !> last contact goes to MPDISP2 (both bodies, c sum_k I(p - k) F_k); a pixel whose gap
   !> is then negative is a missed contact: it is added and the state at the final load
   !> recomputed exactly. Without missed contacts, the exact solve measures the drift of
   !> the step accumulation.
   subroutine final_check(ws, at, n, cstep, step, table, csum, mat, problem, options, path, res, checks, status)
      type(workspace_type), intent(inout) :: ws
      type(legacy_pointers), intent(in) :: at
      integer, intent(inout) :: n, cstep(:)
      integer, intent(in) :: step
      real(dp), intent(in) :: table(0:, 0:), csum
      type(legacy_materials), intent(in) :: mat
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(load_path), intent(inout) :: path
      type(contact_result), intent(inout) :: res
      type(legacy_diagnostics), intent(inout) :: checks
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: fex(:), g0c(:)
      real(dp) :: aex, scale
      integer :: q, nextra, npix
      integer, allocatable :: extra(:), extra_rank(:), byp(:), ic(:), jc(:)
      npix = problem%np**2
      call missed_contacts(ws, at, n, table, csum, problem%np, options%tie_tolerance, path%approach, extra, &
         extra_rank, nextra)
      checks%missed_final_check = nextra
      if (nextra > 0 .and. path%room_for(n, nextra)) then
         ! In pixel order, as the search over all pixels finds them.
         allocate(byp(nextra))
         call merge_sort_index(real(extra(1:nextra), dp), byp)
         do q = 1, nextra
            call add_contact(ws, at, n, cstep, extra(byp(q)), extra_rank(byp(q)), step)
         end do
      end if
      call contact_rows_cols(ws, n, ic, jc)
      allocate(g0c(n), fex(n))
      do q = 1, n
         g0c(q) = ws%ra(at%gaps + ws%ia(at%cont + q - 1) - 1)
      end do
      ! The three springs in series at a contact share the contact material (IPMAT2 and
      ! IPMAT3 name material 3): compliance 3/k.
      call solve_active_set(ic, jc, g0c, csum, 3/mat%penalty, table, path%total, fex, aex, status)
      if (status%code /= 0) return
      associate(ftot => ws%ra(at%force:at%force + n - 1))
         scale = max(maxval(abs(fex)), tiny(1.0_dp))
         checks%final_check_difference = max(abs(aex - path%approach)/max(abs(aex), tiny(1.0_dp)), &
            maxval(abs(fex - ftot))/scale)
         if (nextra > 0) then
            ftot = fex
            path%approach = aex
            res%step_approach(res%nsteps) = aex
            res%step_contacts(res%nsteps) = n
            res%step_above_hardness(res%nsteps) = count(ftot/problem%pixel**2 > options%hardness)
         end if
      end associate
   end subroutine final_check

   !> The pixels off contact whose gap at the last state (g0 - A + the displacement, into
   !> MPDISP2) is below -tie A: the final check's missed contacts, with their gap ranks.
   subroutine missed_contacts(ws, at, n, table, csum, np, tie, approach, extra, extra_rank, nextra)
      type(workspace_type), intent(inout) :: ws
      type(legacy_pointers), intent(in) :: at
      integer, intent(in) :: n, np
      real(dp), intent(in) :: table(0:, 0:), csum, tie, approach
      integer, allocatable, intent(out) :: extra(:), extra_rank(:)
      integer, intent(out) :: nextra
      integer, allocatable :: ic(:), jc(:)
      real(dp) :: gap
      integer :: r, q, idisp, npix
      npix = np*np
      associate(g0 => ws%ra(at%gaps:at%gaps + npix - 1), order => ws%ia(at%sort:at%sort + npix - 1), &
         situ => ws%ia(at%situ:ws%ilast(IPSITU)), ftot => ws%ra(at%force:at%force + n - 1))
         call contact_rows_cols(ws, n, ic, jc)
         idisp = ws%rfirst(MPDISP2)
         allocate(extra(npix), extra_rank(npix))
         nextra = 0
         do r = 1, npix
            q = order(r)
            if (in_contact_at(r, q, situ, ws%ia(at%cont:at%cont + n - 1))) cycle
            ws%ra(idisp + q - 1) = gap_at(0.0_dp, 0.0_dp, csum, table, (q - 1)/np + 1, q - ((q - 1)/np)*np, &
               ic, jc, ftot)
            gap = g0(q) - approach + ws%ra(idisp + q - 1)
            if (gap < -tie*max(approach, tiny(1.0_dp))) then
               nextra = nextra + 1
               extra(nextra) = q
               extra_rank(nextra) = r
            end if
         end do
         ! The handles: the bottom one fixed, the top one moved by the approach.
         ws%ra(idisp + 4*npix) = 0
         ws%ra(idisp + 4*npix + 1) = -approach
      end associate
   end subroutine missed_contacts

   !> The element constants from the material numbers in IPMAT, IPMAT2 and IPMAT3 and
   !> the problem's materials (Young's modulus and Poisson's ratio by number).
   function read_materials(ws, problem) result(mat)
      type(workspace_type), intent(in) :: ws
      type(contact_problem), intent(in) :: problem
      type(legacy_materials) :: mat
      integer :: k, m
      do k = 1, 2
         m = ws%ia(ws%ifirst(IPMAT) + k - 1)
         mat%compliance(k) = surface_compliance(problem%young(m), problem%poisson(m), problem%pixel)
         m = ws%ia(ws%ifirst(IPMAT2) + k - 1)
         mat%interface(k) = spring_stiffness(problem%young(m), problem%poisson(m), problem%pixel, problem%pixel)
      end do
      m = ws%ia(ws%ifirst(IPMAT3))
      mat%penalty = spring_stiffness(problem%young(m), problem%poisson(m), problem%pixel, problem%pixel)
   end function read_materials

   !> Rows and columns of the n contact pixels of IPCONT.
   pure subroutine contact_rows_cols(ws, n, ic, jc)
      type(workspace_type), intent(in) :: ws
      integer, intent(in) :: n
      integer, allocatable, intent(out) :: ic(:), jc(:)
      associate(pix => ws%ia(ws%ifirst(IPCONT):ws%ifirst(IPCONT) + n - 1))
         ic = (pix - 1)/ws%np + 1
         jc = pix - (ic - 1)*ws%np
      end associate
   end subroutine contact_rows_cols

   !> One legacy step for the n contacts of IPCONT: regenerate their nodes (MPCORD,
   !> IPKFIX) and elements (IPNOD1-3), COLHT (IPIADR), assemble BOUSSINESQ (both
   !> surfaces, one flexibility from the substrate nodes' coordinates) and SPRING
   !> (interface and penalty) into MPSTIF, TRFACT factor and solve under the unit load of
   !> MPFEXT. The displacements go to MPDISP, the contact forces per nN to MPWORK(1:n);
   !> returns the approach per nN `delta`. `pixel` is the pixel size (nm).
   subroutine legacy_unit_solution(ws, n, table, mat, pixel, delta, status, pivot_loss, condition)
      type(workspace_type), intent(inout) :: ws
      integer, intent(in) :: n
      real(dp), intent(in) :: table(0:, 0:), pixel
      type(legacy_materials), intent(in) :: mat
      real(dp), intent(out) :: delta
      type(status_type), intent(inout) :: status
      !> TRFACT's estimate of the digits lost (see trfact), for this factorisation.
      real(dp), intent(out), optional :: pivot_loss
      !> LAPACK-style 1-norm condition estimate of the skyline system (trfact_condition).
      real(dp), intent(out), optional :: condition
      real(dp), allocatable :: flex(:, :), kinv(:, :), element(:, :), kcopy(:)
      integer, allocatable :: height(:), eq(:), rows(:), cols(:)
      integer :: neq, nnode, k, e, istif, nstif, inod1, inod2, inod3, icord, iadr0, idisp, iwork, ifext, pix, nfixed
      real(dp) :: spring(2, 2)
      neq = 4*n + 1
      nnode = 4*n + 2
      icord = ws%rfirst(MPCORD)
      inod1 = ws%ifirst(IPNOD1)
      inod2 = ws%ifirst(IPNOD2)
      inod3 = ws%ifirst(IPNOD3)

      ! Nodes: coordinates (nm) of every node, x along the columns, y along the rows,
      ! z by layer (voxels of height d); the bottom handle fixed.
      do k = 1, n
         pix = ws%ia(ws%ifirst(IPCONT) + k - 1)
         call place(1 + k, pix, -1.0_dp)
         call place(1 + n + 2*k - 1, pix, 0.0_dp)
         call place(1 + n + 2*k, pix, 0.0_dp)
         call place(1 + 3*n + k, pix, 1.0_dp)
      end do
      ws%ra(icord:icord + 2) = [0.5_dp, 0.5_dp, -2.0_dp]*ws%np*pixel
      ws%ra(icord + 3*(nnode - 1):icord + 3*nnode - 1) = [0.5_dp, 0.5_dp, 2.0_dp]*ws%np*pixel
      ws%ia(ws%ifirst(IPKFIX):ws%ifirst(IPKFIX) + nnode - 1) = 0
      ws%ia(ws%ifirst(IPKFIX)) = 1
      ! Elements, element by element: two Boussinesq elements (substrate nodes and their
      ! handle), an interface spring on each side of every contact, a penalty spring.
      do k = 1, n
         ws%ia(inod1 + k - 1) = 1 + k
         ws%ia(inod1 + n + k) = 1 + 3*n + k
         ws%ia(inod2 + 4*(k - 1):inod2 + 4*k - 1) = [1 + k, 1 + n + 2*k - 1, 1 + n + 2*k, 1 + 3*n + k]
         ws%ia(inod3 + 2*(k - 1):inod3 + 2*k - 1) = [1 + n + 2*k - 1, 1 + n + 2*k]
      end do
      ws%ia(inod1 + n) = 1
      ws%ia(inod1 + 2*n + 1) = nnode
      ! Equation numbers from IPKFIX: the nodes in order, fixed ones eliminated (0).
      allocate(eq(nnode))
      nfixed = 0
      do k = 1, nnode
         if (ws%ia(ws%ifirst(IPKFIX) + k - 1) == 1) then
            nfixed = nfixed + 1
            eq(k) = 0
         else
            eq(k) = k - nfixed
         end if
      end do
      ! COLHT over all elements.
      allocate(height(neq))
      height = 0
      call colht(eq(ws%ia(inod1:inod1 + n)), height)
      call colht(eq(ws%ia(inod1 + n + 1:inod1 + 2*n + 1)), height)
      do k = 1, n
         call colht(eq(ws%ia(inod2 + 4*(k - 1):inod2 + 4*k - 3)), height)
         call colht(eq(ws%ia(inod2 + 4*k - 2:inod2 + 4*k - 1)), height)
         call colht(eq(ws%ia(inod3 + 2*(k - 1):inod3 + 2*k - 1)), height)
      end do
      iadr0 = ws%ifirst(IPIADR)
      call diagonal_addresses(height, ws%ia(iadr0:iadr0 + neq - 1))
      nstif = ws%ia(iadr0 + neq - 1)
      if (nstif > ws%real_blocks(MPSTIF)%size) then
         call set_error(status, STATUS_NUMERICAL, "legacy: the skyline outgrew MPSTIF")
         return
      end if
      istif = ws%rfirst(MPSTIF)
      idisp = ws%rfirst(MPDISP)
      iwork = ws%rfirst(MPWORK)
      ifext = ws%rfirst(MPFEXT)
      associate(a => ws%ra(istif:istif + nstif - 1), iadr => ws%ia(iadr0:iadr0 + neq - 1), &
         b => ws%ra(idisp:idisp + neq - 1), r => ws%ra(iwork:iwork + neq - 1))
         a = 0
         ! BOUSSINESQ: one flexibility from the substrate nodes' coordinates (pixel
         ! offsets), inverted once, scaled by each surface's material.
         allocate(rows(n), cols(n))
         do k = 1, n
            e = ws%ia(inod1 + k - 1)
            cols(k) = nint(ws%ra(icord + 3*(e - 1))/pixel + 0.5_dp)
            rows(k) = nint(ws%ra(icord + 3*(e - 1) + 1)/pixel + 0.5_dp)
         end do
         flex = boussinesq_flexibility(rows, cols, table)
         allocate(kinv(n, n), element(n + 1, n + 1))
         call boussinesq_inverse(flex, kinv, status)
         if (status%code /= 0) return
         call boussinesq_element(kinv, mat%compliance(1), element)
         call assemble_element(element, eq(ws%ia(inod1:inod1 + n)), iadr, a)
         call boussinesq_element(kinv, mat%compliance(2), element)
         call assemble_element(element, eq(ws%ia(inod1 + n + 1:inod1 + 2*n + 1)), iadr, a)
         ! SPRING, twice: interface springs, then penalty springs.
         do k = 1, n
            spring = spring_element(mat%interface(1))
            call assemble_element(spring, eq(ws%ia(inod2 + 4*(k - 1):inod2 + 4*k - 3)), iadr, a)
            spring = spring_element(mat%interface(2))
            call assemble_element(spring, eq(ws%ia(inod2 + 4*k - 2:inod2 + 4*k - 1)), iadr, a)
         end do
         spring = spring_element(mat%penalty)
         do k = 1, n
            call assemble_element(spring, eq(ws%ia(inod3 + 2*(k - 1):inod3 + 2*k - 1)), iadr, a)
         end do
         ! The external loads by node: -1 nN on the top handle.
         ws%ra(ifext:ifext + nnode - 1) = 0
         ws%ra(ifext + nnode - 1) = -1
         ! TRFACT twice: factorise, then solve for the loads. The rigid body and the rigid
         ! springs make K stiff by five orders of magnitude across its entries; one step
         ! of iterative refinement with the assembled K (kept aside before the
         ! factorisation) restores the digits that costs.
         do k = 1, nnode
            if (eq(k) > 0) b(eq(k)) = ws%ra(ifext + k - 1)
         end do
         kcopy = a
         call trfact(a, iadr, b, TRFACT_FACTOR, status, pivot_loss)
         if (status%code /= 0) return
         if (present(condition)) condition = trfact_condition(a, kcopy, iadr)
         call trfact(a, iadr, b, TRFACT_SOLVE, status)
         call skyline_matvec(kcopy, iadr, b, r)
         do k = 1, nnode
            if (eq(k) > 0) r(eq(k)) = ws%ra(ifext + k - 1) - r(eq(k))
         end do
         call trfact(a, iadr, r, TRFACT_SOLVE, status)
         b = b + r
         delta = -b(eq(nnode))
         ! The contact forces per nN into the work array (the residual is no longer needed).
         do k = 1, n
            ws%ra(iwork + k - 1) = mat%penalty*(b(eq(ws%ia(inod3 + 2*k - 2))) - b(eq(ws%ia(inod3 + 2*k - 1))))
         end do
      end associate
   contains
      !> Node `node` of the contact at pixel `pix`, at layer height z (in pixels).
      subroutine place(node, pix, z)
         integer, intent(in) :: node, pix
         real(dp), intent(in) :: z
         integer :: i, j
         i = (pix - 1)/ws%np + 1
         j = pix - (i - 1)*ws%np
         ws%ra(icord + 3*(node - 1):icord + 3*node - 1) = [(j - 0.5_dp)*pixel, (i - 0.5_dp)*pixel, z*pixel]
      end subroutine place
   end subroutine legacy_unit_solution
end module femcod_legacy
