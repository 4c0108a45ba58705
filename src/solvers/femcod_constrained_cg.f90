!> The constrained conjugate-gradient iteration of Polonsky and Keer (Wear 231, 1999,
!> 206-219) at one total load or at one approach, written once against the elastic operator
!> (model/femcod_elastic_operator): every loop runs over this process's columns, every sum
!> and maximum over the grid goes through the operator's reductions, so femcod-mpi runs
!> this same iteration on its slabs. What the iteration does and why each acceleration
!> keeps the answer: femcod_cg's header.
!>
!> The iteration's state is one derived type (cg_iteration), and each part of an
!> iteration a routine of its own: the gaps at the contacts, the residual, the search
!> direction and its step length, the step and the projection, the corrections of the
!> displacements for the forces the projection changed.
!>
!> No I/O and no stop.
module femcod_constrained_cg
   use, intrinsic :: iso_fortran_env, only: int8
   use femcod_kinds, only: dp, sp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL, STATUS_INTERRUPTED
   use femcod_elastic_operator, only: elastic_operator, cg_constraint
   use femcod_solver_options, only: cg_settings
   use femcod_observer, only: solver_observer
   use femcod_strings, only: count_text, int_str
   !$ use omp_lib, only: omp_get_max_threads, omp_get_thread_num
   implicit none
   private
   public :: constrained_cg, cg_residuals

   !> What the CG solver reached at one load.
   type :: cg_residuals
      !> Iterations on the full grid, and on all coarser grids together.
      integer :: iterations = 0, coarse_iterations = 0
      !> Fresh convolutions of the forces on the full grid (when more than
      !> `direct_corrections` forces changed and the kernel split may not take them, at
      !> the switch to double, and for the final check); each iteration convolves its
      !> search direction besides. Corrections by the kernel split.
      integer :: convolutions = 0, split_corrections = 0
      real(dp) :: penetration = 0, contact_gap = 0, load_error = 0, residual = 0
   end type cg_residuals

   !> Pixels (i, j) in the order one thread found them (pixels entering the contacts).
   type :: pixel_list
      integer :: n = 0
      integer, allocatable :: ij(:, :)
   end type pixel_list

   !> One constrained iteration's state (constrained_cg).
   !>
   !> No array of the gaps: they are g0 + alpha (w + s p) - gbar, formed where they are
   !> used, and gm keeps them in float32 on the contacts (zero elsewhere, two pixels of
   !> padding for the stencil) for the direction and its step, which the gaps recomputed
   !> in double each iteration correct; nor of the preconditioned gaps z (stencil_at,
   !> formed twice). The direction t is zero off the contacts, so it is kept on the
   !> contacts only, and scattered for its convolution into r, which the convolution
   !> then overwrites with t's displacements; r is float32 (r32) when the transform
   !> making it is. At NP = 4096 each NP x NP array is 134 MB in double.
   type :: cg_iteration
      !> Rows and this process's columns; c and s (nm/nN).
      integer :: np = 0, nj = 0
      real(dp) :: c = 0, s = 0
      !> Displacements of the stored forces w and of the direction r (nm); the direction
      !> t (nN) at the contacts, in the order of `contact`.
      real(dp), allocatable :: w(:, :), r(:, :), t(:)
      real(sp), allocatable :: gm(:, :), r32(:, :)
      !> The contact pixels (p > 0) as (i, j), column by column, and on the grid as 1 in
      !> `touching` (one byte a pixel, for the pass over all pixels).
      integer, allocatable :: contact(:, :)
      integer(int8), allocatable :: touching(:, :)
      !> The previous gaps at the contacts, in the order of `contact`, for beta and
      !> Powell's test (float32 is enough). A pixel that enters keeps its gap in gm until
      !> the next iteration reads it here.
      real(sp), allocatable :: g_old(:)
      !> The pixels each thread found entering in one step, in column order.
      type(pixel_list), allocatable :: entering(:)
      integer :: threads = 1
      !> The force changes the projection made (up to `capacity` kept), their number here
      !> and on the whole grid; how many the operator corrects directly and by its split.
      integer, allocatable :: changed(:, :)
      real(dp), allocatable :: delta(:)
      integer :: nchanged = 0, nchanged_all = 0, limit = 0, split_limit = 0, capacity = 0
      !> The contacts here and on the whole grid.
      integer :: nc = 0
      real(dp) :: nc_all = 0
      !> The load balance alpha (forces and displacements are alpha times p and w until
      !> the next step writes them scaled), the contacts' mean gap, the (preconditioned)
      !> gradient norms and their cross term, beta, the direction's mean, the step.
      !> Under displacement control (by_approach) gbar is the approach, and alpha the
      !> balance that puts the contacts' mean gap there.
      real(dp) :: alpha = 1, gbar = 0, big_g = 0, big_g_old = 1, cross = 0, beta = 0, zbar = 0, tau = 0
      !> An entering pixel's share of a lone pixel's preconditioned step; the forces' sum.
      real(dp) :: entry = 1, psum = 0
      real(dp) :: residual = 0, contact_gap = 0, penetration = 0
      !> The length (nm) the residual is measured against: the height range, or where
      !> larger the contacts' largest elastic displacement or a pixel's own displacement
      !> under its force (a flat or nearly flat surface, whose height range is 0 or below
      !> the round-off of the displacements: issue 47's degenerate family).
      real(dp) :: scale = 1
      !> The error bound (nm) of the split corrections since the last fresh convolution.
      real(dp) :: split_error = 0
      integer :: it = 0
      logical :: by_approach = .false.
      logical :: restart = .true., single = .false., fresh = .true., fresh_double = .false., stalled = .false., &
         keep_old = .false., kept_old = .false.
   end type cg_iteration


   !> Sums over the contacts are taken by blocks of this many contacts, each block's sum in
   !> list order, then the blocks' sums in order: the grouping is the same on any number
   !> of threads, and so is every bit of the answer (issue 47).
   integer, parameter :: SUM_BLOCK = 4096
contains

   !> Polonsky-Keer constrained CG on the operator `grid` under `target` from the forces
   !> p (nN, any positive start; returned: the solution). At a total load P, `approach`
   !> (nm) is the mean gap of the contact pixels before the rigid shift, i.e. the approach
   !> from first touch. At an approach A the same iteration runs with A for that mean and
   !> the load balance alpha chosen to match it (contact_gaps): the load, sum p, is the
   !> answer.
   !>
   !> Only two things need every pixel in each iteration: the convolution, and one pass
   !> that moves the displacements by the step and lets overlapping pixels enter. All else
   !> (the contacts' gaps, the preconditioner, the direction, the step length, the
   !> projection) runs over the list of contact pixels, which is 1 to 10 % of the grid at
   !> the loads users ask for: at NP = 4096 the passes over all pixels moved 3.4 GB a
   !> iteration before, 0.5 GB now. The penetration off the contacts, which needs every
   !> pixel, is evaluated only when the contacts' own residual is below a threshold the
   !> test compares with (tol, single_until, or at the last iteration): above it the
   !> residual is above the threshold whatever the penetration, so every decision is the
   !> one the full residual would give.
   subroutine constrained_cg(grid, target, tol, max_iterations, how, p, approach, rep, status, observer, final_gap)
      class(elastic_operator), intent(inout) :: grid
      type(cg_constraint), intent(in) :: target
      real(dp), intent(in) :: tol
      integer, intent(in) :: max_iterations
      type(cg_settings), intent(in) :: how
      real(dp), intent(inout) :: p(:, :)
      real(dp), intent(out) :: approach
      type(cg_residuals), intent(inout) :: rep
      type(status_type), intent(inout) :: status
      !> Asked every iteration whether to stop (a stop signal).
      class(solver_observer), intent(inout) :: observer
      !> The gap (nm) of the solution, from the last fresh double-precision convolution,
      !> 0 at the contacts: the gap map of this load (solvers/femcod_maps), without a
      !> convolution of its own.
      real(dp), allocatable, intent(out), optional :: final_gap(:, :)
      type(cg_iteration) :: st
      call iteration_start(st, grid, how, p, target)
      do
         if (grid%any_over_grid(observer%stop_requested())) then
            call set_error(status, STATUS_INTERRUPTED, "stopped after "//count_text(st%it, "iteration")//" on the "// &
               int_str(st%np)//" x "//int_str(st%np)//" grid")
            return
         end if
         if (st%fresh) then
            call displacements(st, grid, p, st%w, rep)
            st%split_error = 0
            st%fresh = .false.
            st%stalled = .false.
         end if
         call contact_gaps(st, grid, p, status)
         if (status%code /= 0) return
         approach = st%gbar
         call measure_residual(st, grid, tol, max_iterations, how)
         if (st%residual < tol .or. st%it >= max_iterations .or. st%stalled) then
            ! Accept only on displacements from a fresh double-precision convolution.
            if (.not. st%fresh_double) then
               st%single = .false.
               st%fresh = .true.
               cycle
            end if
            exit
         end if
         ! The split corrections' error bound stays below split_tolerance times the
         ! residual: once the residual has fallen to it, the displacements afresh and new
         ! directions.
         if (st%split_error > how%split_tolerance*st%residual*st%scale) then
            st%fresh = .true.
            st%restart = .true.
            cycle
         end if
         if (st%single .and. st%residual < how%single_until) then
            st%single = .false.
            st%fresh = .true.
            cycle
         end if
         call search_direction(st, grid, how)
         ! Nothing left to move on the contacts: the forces are the solution to round-off,
         ! accepted at the top of the loop on fresh displacements; unless pixels off the
         ! contacts overlap, which then join them.
         if (st%stalled) then
            call join_overlapping(st, grid)
            cycle
         end if
         call take_step(st, grid, how, p, status)
         if (status%code /= 0) return
         call correct_displacements(st, grid, how, rep)
         ! The step wrote the forces scaled: the next balance from them.
         if (st%by_approach) then
            st%alpha = 1
         else
            st%alpha = target%value/st%psum
         end if
      end do
      call iteration_finish(st, grid, p, target, rep, final_gap)
   end subroutine constrained_cg

   !> The state for a solve from the forces p under `target`: the arrays, the start's
   !> contacts (the direction, zero at first, is kept on the contacts only: it is zero
   !> off them throughout) and the load balance (1 at an approach, which fixes gbar
   !> instead).
   subroutine iteration_start(st, grid, how, p, target)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      type(cg_settings), intent(in) :: how
      real(dp), intent(in) :: p(:, :)
      type(cg_constraint), intent(in) :: target
      real(dp) :: total(1)
      integer :: np, nj, i, j
      np = grid%np
      nj = grid%nj
      st%np = np
      st%nj = nj
      st%c = grid%c
      st%s = grid%s
      call grid%correction_limits(how, st%limit, st%split_limit)
      st%capacity = max(st%limit, st%split_limit)
      st%threads = 1
      !$ st%threads = omp_get_max_threads()
      allocate(st%w(np, nj), st%gm(-1:np + 2, -1:nj + 2), st%changed(2, st%capacity), &
         st%delta(st%capacity), st%touching(np, nj), st%entering(0:st%threads - 1))
      if (how%single_until > 0) then
         allocate(st%r32(np, nj))
      else
         allocate(st%r(np, nj))
      end if
      st%gm = 0
      ! The previous gradient, for Polak-Ribiere's beta and for Powell's restart test.
      st%keep_old = how%polak_ribiere .or. how%powell_restart > 0
      ! Overlapping pixels enter with a share (entry_scale) of the preconditioned step's
      ! force for a lone pixel.
      st%entry = 1
      if (grid%preconditioned) st%entry = how%entry_scale*grid%taps(0, 0)
      !$omp parallel do private(i)
      do j = 1, nj
         do i = 1, np
            st%touching(i, j) = merge(1_int8, 0_int8, p(i, j) > 0)
         end do
      end do
      call list_contacts(st)
      total(1) = sum(p)
      call grid%sum_over_grid(total)
      st%by_approach = target%by_approach
      if (st%by_approach) then
         st%alpha = 1
         st%gbar = target%value
      else
         st%alpha = target%value/total(1)
      end if
      st%single = how%single_until > 0
   end subroutine iteration_start

   !> The contacts' mean gap gbar (the approach), their residual (the largest |gap|), the
   !> gradient's norm and its cross term with the previous one, and their gaps in gm for
   !> the preconditioner; the previous gaps taken from gm first, once an iteration. An
   !> error when no contact is left.
   subroutine contact_gaps(st, grid, p, status)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      real(dp), intent(in) :: p(:, :)
      type(status_type), intent(inout) :: status
      real(dp) :: gbar, big_g, cross, contact_gap, gij, alpha, a, s, sums(3), pair(2), lift, own
      real(dp), allocatable :: part(:, :)
      integer :: q, i, j, nc, b, nb
      logical :: take_old
      nc = size(st%contact, 2)
      st%nc = nc
      alpha = st%alpha
      s = st%s
      ! Sums over the contacts by blocks of SUM_BLOCK, then the blocks in order: the same
      ! bits on any number of threads (the list is in column order, the blocks fixed).
      nb = (nc + SUM_BLOCK - 1)/SUM_BLOCK
      allocate(part(4, nb))
      ! The contacts' gaps before the shift, g0 + alpha (w + s p), summed; at an approach
      ! their two parts apart (a = 0: the g0 alone), for the balance below.
      a = merge(0.0_dp, alpha, st%by_approach)
      !$omp parallel do private(q, i, j)
      do b = 1, nb
         part(1:2, b) = 0
         do q = (b - 1)*SUM_BLOCK + 1, min(b*SUM_BLOCK, nc)
            i = st%contact(1, q)
            j = st%contact(2, q)
            part(1, b) = part(1, b) + (grid%g0(i, j) + a*(st%w(i, j) + s*p(i, j)))
            if (st%by_approach) part(2, b) = part(2, b) + (st%w(i, j) + s*p(i, j))
         end do
      end do
      sums = [sum(part(1, :)), sum(part(2, :)), real(nc, dp)]
      call grid%sum_over_grid(sums)
      st%nc_all = sums(3)
      if (.not. st%nc_all > 0) then
         call set_error(status, STATUS_NUMERICAL, "cg: all forces vanished")
         return
      end if
      if (st%by_approach) then
         ! Displacement control: the load balance that puts the contacts' mean gap at the
         ! approach, mean(g0 + alpha (w + s p)) = A (kept where it would not be positive),
         ! so the directions, which keep the load, need not find the mean (the slowest
         ! mode) themselves.
         if (sums(2) > 0 .and. st%gbar*sums(3) - sums(1) > 0) st%alpha = (st%gbar*sums(3) - sums(1))/sums(2)
         alpha = st%alpha
         gbar = st%gbar
      else
         gbar = sums(1)/st%nc_all
         st%gbar = gbar
      end if
      ! A pixel's own displacement per nN: the convolution's round-off scales with the
      ! forces, and on a periodic cell a uniform pressure displaces nothing, so the
      ! scale holds this too (a periodic flat with 1e-12 nm ripples stalled at 1.2e-6).
      own = alpha*(grid%c*grid%self + s)
      take_old = st%keep_old .and. .not. st%kept_old
      if (take_old) then
         if (allocated(st%g_old)) deallocate(st%g_old)
         allocate(st%g_old(nc))
      end if
      big_g = 0
      cross = 0
      contact_gap = 0
      lift = 0
      !$omp parallel do private(q, i, j, gij) reduction(max:contact_gap, lift)
      do b = 1, nb
         part(1:2, b) = 0
         do q = (b - 1)*SUM_BLOCK + 1, min(b*SUM_BLOCK, nc)
            i = st%contact(1, q)
            j = st%contact(2, q)
            lift = max(lift, abs(alpha*(st%w(i, j) + s*p(i, j))), own*p(i, j))
            gij = grid%g0(i, j) + alpha*(st%w(i, j) + s*p(i, j)) - gbar
            if (take_old) st%g_old(q) = st%gm(i, j)
            part(1, b) = part(1, b) + gij**2
            if (st%keep_old .and. .not. grid%preconditioned) part(2, b) = part(2, b) + gij*real(st%g_old(q), dp)
            contact_gap = max(contact_gap, abs(gij))
            st%gm(i, j) = real(gij, sp)
         end do
      end do
      big_g = sum(part(1, :))
      cross = sum(part(2, :))
      st%kept_old = st%keep_old
      pair = [big_g, cross]
      call grid%sum_over_grid(pair)
      st%big_g = pair(1)
      st%cross = pair(2)
      pair = [contact_gap, lift]
      call grid%max_over_grid(pair)
      st%contact_gap = pair(1)
      st%scale = max(grid%scale, pair(2))
   end subroutine contact_gaps

   !> The relative residual max(contact gap, penetration) / scale (the height range, or
   !> the contacts' largest displacement where larger), with the
   !> penetration off the contacts evaluated only where a decision depends on it.
   subroutine measure_residual(st, grid, tol, max_iterations, how)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      real(dp), intent(in) :: tol
      integer, intent(in) :: max_iterations
      type(cg_settings), intent(in) :: how
      real(dp) :: threshold, depth(1)
      threshold = tol
      if (st%single) threshold = max(tol, how%single_until)
      if (st%contact_gap/st%scale < threshold .or. st%it >= max_iterations .or. st%stalled) then
         depth(1) = deepest_overlap(st, grid)
         call grid%max_over_grid(depth)
         st%penetration = depth(1)
      else
         st%penetration = 0
      end if
      st%residual = max(st%contact_gap, st%penetration)/st%scale
   end subroutine measure_residual

   !> The next search direction t on the contacts (the preconditioned gaps with beta by
   !> Polak-Ribiere+ or Fletcher-Reeves, Powell's restart), its displacements r, and the
   !> step length tau that minimises along it with the load kept; `stalled` when the
   !> direction cannot move the forces.
   subroutine search_direction(st, grid, how)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      type(cg_settings), intent(in) :: how
      real(dp) :: num, rt, rsum, tsum, rbar, den, beta, zbar, s, sums(4)
      real(dp), allocatable :: part(:, :)
      integer :: q, i, j, b, nb
      if (grid%preconditioned) then
         call grid%exchange_halo(st%gm)
         call precondition(st, grid)
      end if
      st%it = st%it + 1
      if (how%powell_restart > 0 .and. abs(st%cross) >= how%powell_restart*st%big_g) st%restart = .true.
      if (st%restart .or. .not. st%big_g_old > 0) then
         st%beta = 0
      else if (how%polak_ribiere) then
         st%beta = max(0.0_dp, (st%big_g - st%cross)/st%big_g_old)
      else
         st%beta = st%big_g/st%big_g_old
      end if
      st%big_g_old = st%big_g
      beta = st%beta
      zbar = st%zbar
      ! Sums by blocks of contacts, then the blocks in order (thread-count independent).
      nb = (st%nc + SUM_BLOCK - 1)/SUM_BLOCK
      allocate(part(3, nb))
      !$omp parallel do private(q, i, j)
      do b = 1, nb
         part(1, b) = 0
         do q = (b - 1)*SUM_BLOCK + 1, min(b*SUM_BLOCK, st%nc)
            i = st%contact(1, q)
            j = st%contact(2, q)
            if (grid%preconditioned) then
               st%t(q) = stencil_at(st, grid%taps, i, j) - zbar + beta*st%t(q)
            else
               st%t(q) = real(st%gm(i, j), dp) + beta*st%t(q)
            end if
            part(1, b) = part(1, b) + real(st%gm(i, j), dp)*st%t(q)
         end do
      end do
      num = sum(part(1, :))
      ! r = c (I * t): the displacements of the search direction, always in float32
      ! when float32 is on: its round-off (1e-7 of r) scales with the step, and the
      ! steps shrink with the residual, so it never limits the accuracy; the forces'
      ! own displacements (fresh) switch to double below `single_until`. t is scattered
      ! into r's storage (as the transform rounds it) and replaced there.
      call scatter_direction(st)
      if (allocated(st%r32)) then
         call grid%displace_single_in_place(st%r32)
      else
         call grid%displace_in_place(st%r)
      end if
      st%fresh_double = .false.
      s = st%s
      !$omp parallel do private(q, i, j)
      do b = 1, nb
         part(:, b) = 0
         do q = (b - 1)*SUM_BLOCK + 1, min(b*SUM_BLOCK, st%nc)
            i = st%contact(1, q)
            j = st%contact(2, q)
            part(1, b) = part(1, b) + (r_at(st, i, j) + s*st%t(q))*st%t(q)
            part(2, b) = part(2, b) + r_at(st, i, j) + s*st%t(q)
            part(3, b) = part(3, b) + st%t(q)
         end do
      end do
      rt = sum(part(1, :))
      rsum = sum(part(2, :))
      tsum = sum(part(3, :))
      sums = [num, rt, rsum, tsum]
      call grid%sum_over_grid(sums)
      rbar = sums(3)/st%nc_all
      den = sums(2) - rbar*sums(4)
      if (.not. abs(den) > 0) then
         st%stalled = .true.
         return
      end if
      st%tau = sums(1)/den
   end subroutine search_direction

   !> The step. Every pixel: the displacements follow linearly (w - tau r), and an
   !> overlapping pixel enters. Then the contacts: their forces step and are clipped at
   !> zero. Where the projection changed a force, the displacements need a correction:
   !> the first `capacity` changes are kept (in any order; sorted by
   !> correct_displacements). The contact list follows; the forces' sum into st%psum.
   subroutine take_step(st, grid, how, p, status)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      type(cg_settings), intent(in) :: how
      real(dp), intent(inout) :: p(:, :)
      type(status_type), intent(inout) :: status
      real(dp) :: psum, psum_in, gij, pn, lin, alpha, tau, gbar, entry, sums(4)
      real(dp), allocatable :: part(:, :), entered(:)
      integer :: q, i, j, thread, nchanged, b, nb
      alpha = st%alpha
      tau = st%tau
      gbar = st%gbar
      entry = st%entry
      nchanged = 0
      ! The entering forces summed by column, then the columns in order: the same bits on
      ! any number of threads.
      allocate(entered(st%nj))
      st%entering%n = 0
      !$omp parallel private(thread, i, j, gij, pn)
      thread = 0
      !$ thread = omp_get_thread_num()
      !$omp do schedule(static)
      do j = 1, st%nj
         entered(j) = 0
         do i = 1, st%np
            if (st%touching(i, j) == 0) then
               gij = grid%g0(i, j) + alpha*st%w(i, j) - gbar
               if (gij < 0) then
                  pn = -tau*entry*gij
                  p(i, j) = pn
                  entered(j) = entered(j) + pn
                  st%touching(i, j) = 1
                  ! Its gap now is its previous gap in the next iteration.
                  st%gm(i, j) = real(gij, sp)
                  call push_pixel(st%entering(thread), i, j)
                  call record_change(st, nchanged, i, j, pn)
               end if
            end if
            st%w(i, j) = alpha*st%w(i, j) - tau*r_at(st, i, j)
         end do
      end do
      !$omp end do
      !$omp end parallel
      psum_in = sum(entered)
      nb = (st%nc + SUM_BLOCK - 1)/SUM_BLOCK
      allocate(part(1, nb))
      !$omp parallel do private(q, i, j, lin, pn)
      do b = 1, nb
         part(1, b) = 0
         do q = (b - 1)*SUM_BLOCK + 1, min(b*SUM_BLOCK, st%nc)
            i = st%contact(1, q)
            j = st%contact(2, q)
            lin = alpha*p(i, j) - tau*st%t(q)
            pn = max(lin, 0.0_dp)
            p(i, j) = pn
            part(1, b) = part(1, b) + pn
            if (.not. pn > 0) then
               ! Leaves the contacts: no force, no contact gap (and no direction: the
               ! list after the step drops it).
               st%touching(i, j) = 0
               st%gm(i, j) = 0
            end if
            if (pn /= lin) call record_change(st, nchanged, i, j, pn - lin)
         end do
      end do
      psum = sum(part(1, :))
      st%nchanged = nchanged
      sums = [psum, psum_in, real(nchanged, dp), real(sum(st%entering%n), dp)]
      call grid%sum_over_grid(sums)
      st%nchanged_all = nint(sums(3))
      st%restart = how%restart_on_entry .and. sums(4) > 0
      call list_contacts_after_step(st)
      st%kept_old = .false.
      st%fresh_double = .false.
      st%psum = sums(1) + sums(2)
      if (.not. st%psum > 0) call set_error(status, STATUS_NUMERICAL, "cg: all forces vanished")
   end subroutine take_step

   !> The displacements corrected for the forces the projection changed: a few directly
   !> from the table, more by the kernel split while its error bound since the last fresh
   !> convolution stays a fraction of the residual (nm), else a fresh convolution at the
   !> top of the next iteration (the operator says how many it takes).
   subroutine correct_displacements(st, grid, how, rep)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      type(cg_settings), intent(in) :: how
      type(cg_residuals), intent(inout) :: rep
      logical :: applied
      if (st%nchanged > 0 .and. st%nchanged <= st%capacity) call sort_changes(st, st%nchanged)
      if (st%nchanged_all > st%limit .and. st%nchanged_all <= st%split_limit) then
         call grid%split_correct(st%w, st%changed, st%delta, st%nchanged, how, &
            how%split_tolerance*st%residual*st%scale, st%split_error, applied)
         if (applied) then
            rep%split_corrections = rep%split_corrections + 1
            st%fresh_double = .false.
         else
            st%fresh = .true.
         end if
      else if (st%nchanged_all > st%limit) then
         st%fresh = .true.
      else if (st%nchanged_all > 0) then
         call grid%add_direct(st%w, st%changed, st%delta, st%nchanged)
         st%fresh_double = .false.
      end if
   end subroutine correct_displacements

   !> The answer: the forces with the load balance applied, the residuals reached, and
   !> the gap map (formed in w's storage and handed over: no further NP x NP array at
   !> the peak).
   subroutine iteration_finish(st, grid, p, target, rep, final_gap)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      real(dp), intent(inout) :: p(:, :)
      type(cg_constraint), intent(in) :: target
      type(cg_residuals), intent(inout) :: rep
      real(dp), allocatable, intent(out), optional :: final_gap(:, :)
      real(dp) :: total(1), alpha, gbar
      integer :: q, i, j
      alpha = st%alpha
      gbar = st%gbar
      !$omp parallel do private(i, j)
      do q = 1, size(st%contact, 2)
         i = st%contact(1, q)
         j = st%contact(2, q)
         p(i, j) = alpha*p(i, j)
      end do
      rep%iterations = rep%iterations + st%it
      rep%residual = st%residual
      rep%contact_gap = st%contact_gap
      rep%penetration = st%penetration
      total(1) = sum(p)
      call grid%sum_over_grid(total)
      ! At an approach the load is the answer: no constraint on it to miss.
      rep%load_error = 0
      if (.not. st%by_approach) rep%load_error = abs(total(1) - target%value)/target%value
      if (.not. present(final_gap)) return
      if (allocated(st%r)) deallocate(st%r)
      if (allocated(st%r32)) deallocate(st%r32)
      !$omp parallel do private(i)
      do j = 1, st%nj
         do i = 1, st%np
            if (st%touching(i, j) /= 0) then
               st%w(i, j) = 0
            else
               st%w(i, j) = grid%g0(i, j) + alpha*st%w(i, j) - gbar
            end if
         end do
      end do
      call move_alloc(st%w, final_gap)
   end subroutine iteration_finish

   !> out = c (I * f) with fresh transforms (float32 while `single`), counted.
   subroutine displacements(st, grid, f, out, rep)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out) :: out(:, :)
      type(cg_residuals), intent(inout) :: rep
      if (st%single) then
         call grid%displace_single(f, out)
      else
         call grid%displace(f, out)
      end if
      rep%convolutions = rep%convolutions + 1
      st%fresh_double = .not. st%single
   end subroutine displacements

   !> The deepest overlap (nm) off the contacts, max(-gap, 0), over this part's pixels.
   real(dp) function deepest_overlap(st, grid) result(depth)
      type(cg_iteration), intent(in) :: st
      class(elastic_operator), intent(in) :: grid
      real(dp) :: alpha, gbar
      integer :: ii, jj
      alpha = st%alpha
      gbar = st%gbar
      depth = 0
      !$omp parallel do private(ii) reduction(max:depth)
      do jj = 1, st%nj
         do ii = 1, st%np
            if (st%touching(ii, jj) == 0) depth = max(depth, -(grid%g0(ii, jj) + alpha*st%w(ii, jj) - gbar))
         end do
      end do
   end function deepest_overlap

   !> A direction that cannot move the forces (every contact's gap the same, as with a
   !> single contact after a warm start from a smaller load) leaves overlapping pixels off
   !> the contacts where they are: they enter only with a step. Such pixels join the
   !> contacts with no force, so that the next direction, restarted, moves force onto
   !> them; `stalled` stays only when none overlaps on any process.
   subroutine join_overlapping(st, grid)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      real(dp) :: joined(1)
      integer :: ii, jj
      joined = 0
      !$omp parallel do private(ii) reduction(+:joined)
      do jj = 1, st%nj
         do ii = 1, st%np
            if (st%touching(ii, jj) == 0 .and. grid%g0(ii, jj) + st%alpha*st%w(ii, jj) - st%gbar < 0) then
               st%touching(ii, jj) = 1
               joined(1) = joined(1) + 1
            end if
         end do
      end do
      call grid%sum_over_grid(joined)
      if (.not. joined(1) > 0) return
      call list_contacts(st)
      st%stalled = .false.
      st%restart = .true.
      st%kept_old = .false.
   end subroutine join_overlapping

   !> `contact` from `touching`: every contact pixel, column by column; the direction
   !> carried over to the pixels that were in the list before (zero at the others).
   subroutine list_contacts(st)
      type(cg_iteration), intent(inout) :: st
      integer, allocatable :: old(:, :)
      real(dp), allocatable :: t_old(:)
      integer :: ii, jj, n, a
      if (allocated(st%contact)) call move_alloc(st%contact, old)
      if (allocated(st%t)) call move_alloc(st%t, t_old)
      allocate(st%contact(2, count(st%touching /= 0)))
      allocate(st%t(size(st%contact, 2)))
      st%t = 0
      n = 0
      a = 1
      do jj = 1, st%nj
         do ii = 1, st%np
            if (st%touching(ii, jj) /= 0) then
               n = n + 1
               st%contact(1, n) = ii
               st%contact(2, n) = jj
               if (.not. allocated(t_old)) cycle
               ! The old list is in the same (column, row) order: walk it alongside.
               do while (a <= size(old, 2))
                  if (old(2, a) > jj .or. (old(2, a) == jj .and. old(1, a) >= ii)) exit
                  a = a + 1
               end do
               if (a <= size(old, 2)) then
                  if (old(1, a) == ii .and. old(2, a) == jj) st%t(n) = t_old(a)
               end if
            end if
         end do
      end do
   end subroutine list_contacts

   !> t scattered into r32 (rounded to float32, as the float32 transform would round it)
   !> or r, zero off the contacts: the direction's field for its convolution in place.
   subroutine scatter_direction(st)
      type(cg_iteration), intent(inout) :: st
      integer :: q, j
      if (allocated(st%r32)) then
         !$omp parallel do
         do j = 1, st%nj
            st%r32(:, j) = 0
         end do
         !$omp parallel do
         do q = 1, size(st%contact, 2)
            st%r32(st%contact(1, q), st%contact(2, q)) = real(st%t(q), sp)
         end do
      else
         !$omp parallel do
         do j = 1, st%nj
            st%r(:, j) = 0
         end do
         !$omp parallel do
         do q = 1, size(st%contact, 2)
            st%r(st%contact(1, q), st%contact(2, q)) = st%t(q)
         end do
      end if
   end subroutine scatter_direction

   !> `contact` after a step: the pixels of the list that kept a force merged with those
   !> that entered (each thread's in column order, the threads' columns in order), so the
   !> list stays in column order and every sum over it in one order; the direction
   !> follows (zero at the pixels that entered).
   subroutine list_contacts_after_step(st)
      type(cg_iteration), intent(inout) :: st
      integer, allocatable :: new(:, :), came(:, :)
      real(dp), allocatable :: new_t(:)
      integer :: n, k, a, b, kept, th
      kept = 0
      do k = 1, size(st%contact, 2)
         if (st%touching(st%contact(1, k), st%contact(2, k)) /= 0) kept = kept + 1
      end do
      allocate(came(2, sum(st%entering%n)), new(2, kept + sum(st%entering%n)), new_t(kept + sum(st%entering%n)))
      n = 0
      do th = 0, st%threads - 1
         if (st%entering(th)%n == 0) cycle
         came(:, n + 1:n + st%entering(th)%n) = st%entering(th)%ij(:, 1:st%entering(th)%n)
         n = n + st%entering(th)%n
      end do
      ! Merge by (column, row).
      associate(contact => st%contact, touching => st%touching)
         a = 1
         b = 1
         n = 0
         do
            do while (a <= size(contact, 2))
               if (touching(contact(1, a), contact(2, a)) /= 0) exit
               a = a + 1
            end do
            if (a > size(contact, 2) .and. b > size(came, 2)) exit
            n = n + 1
            if (b > size(came, 2)) then
               new(:, n) = contact(:, a)
               new_t(n) = st%t(a)
               a = a + 1
            else if (a > size(contact, 2)) then
               new(:, n) = came(:, b)
               new_t(n) = 0
               b = b + 1
            else if (contact(2, a) < came(2, b) .or. (contact(2, a) == came(2, b) .and. contact(1, a) < came(1, b))) then
               new(:, n) = contact(:, a)
               new_t(n) = st%t(a)
               a = a + 1
            else
               new(:, n) = came(:, b)
               new_t(n) = 0
               b = b + 1
            end if
         end do
      end associate
      call move_alloc(new, st%contact)
      call move_alloc(new_t, st%t)
   end subroutine list_contacts_after_step

   !> Count a change of the force at pixel (i, j) by the projection, d (nN), and keep it
   !> among the first `capacity` for a correction (called by the step's threads;
   !> `nchanged` is the step's shared count).
   subroutine record_change(st, nchanged, i, j, d)
      type(cg_iteration), intent(inout) :: st
      integer, intent(inout) :: nchanged
      integer, intent(in) :: i, j
      real(dp), intent(in) :: d
      integer :: slot
      !$omp atomic capture
      nchanged = nchanged + 1
      slot = nchanged
      !$omp end atomic
      if (slot <= st%capacity) then
         st%changed(1, slot) = i
         st%changed(2, slot) = j
         st%delta(slot) = d
      end if
   end subroutine record_change

   !> The displacement (nm) of the search direction at pixel (i, j), from r32 or r.
   pure real(dp) function r_at(st, i, j)
      type(cg_iteration), intent(in) :: st
      integer, intent(in) :: i, j
      if (allocated(st%r32)) then
         r_at = real(st%r32(i, j), dp)
      else
         r_at = st%r(i, j)
      end if
   end function r_at

   !> The 13-point stencil of the inverse Love operator (taps a) on the contacts' gaps gm
   !> at pixel (i, j): the preconditioned gap z.
   pure real(dp) function stencil_at(st, a, i, j)
      type(cg_iteration), intent(in) :: st
      real(dp), intent(in) :: a(0:2, 0:2)
      integer, intent(in) :: i, j
      associate(gm => st%gm)
         stencil_at = a(0, 0)*real(gm(i, j), dp) + a(1, 0)*(real(gm(i - 1, j), dp) + real(gm(i + 1, j), dp)) + &
            a(0, 1)*(real(gm(i, j - 1), dp) + real(gm(i, j + 1), dp)) + &
            a(1, 1)*(real(gm(i - 1, j - 1), dp) + real(gm(i + 1, j - 1), dp) + real(gm(i - 1, j + 1), dp) + &
            real(gm(i + 1, j + 1), dp)) + &
            a(2, 0)*(real(gm(i - 2, j), dp) + real(gm(i + 2, j), dp)) + &
            a(0, 2)*(real(gm(i, j - 2), dp) + real(gm(i, j + 2), dp))
      end associate
   end function stencil_at

   !> z = the stencil applied to the contacts' gaps gm (zero off the contacts), on the
   !> contacts; zbar its mean there (the direction is z - zbar); big_g = g . (z - zbar),
   !> the preconditioned norm for beta, and cross = g_old . (z - zbar) for Polak-Ribiere
   !> and Powell's restart test. z is not kept: the direction forms it again.
   subroutine precondition(st, grid)
      type(cg_iteration), intent(inout) :: st
      class(elastic_operator), intent(inout) :: grid
      real(dp) :: zij, sums(5)
      real(dp), allocatable :: part(:, :)
      integer :: k, ii, jj, b, nb
      logical :: keep_old
      keep_old = st%keep_old
      ! Sums by blocks of contacts, then the blocks in order (thread-count independent).
      nb = (st%nc + SUM_BLOCK - 1)/SUM_BLOCK
      allocate(part(5, nb))
      !$omp parallel do private(k, ii, jj, zij)
      do b = 1, nb
         part(:, b) = 0
         do k = (b - 1)*SUM_BLOCK + 1, min(b*SUM_BLOCK, st%nc)
            ii = st%contact(1, k)
            jj = st%contact(2, k)
            zij = stencil_at(st, grid%taps, ii, jj)
            part(1, b) = part(1, b) + zij
            part(2, b) = part(2, b) + real(st%gm(ii, jj), dp)*zij
            part(3, b) = part(3, b) + real(st%gm(ii, jj), dp)
            if (keep_old) then
               part(4, b) = part(4, b) + real(st%g_old(k), dp)*zij
               part(5, b) = part(5, b) + real(st%g_old(k), dp)
            end if
         end do
      end do
      sums = [(sum(part(k, :)), k = 1, 5)]
      call grid%sum_over_grid(sums)
      st%zbar = sums(1)/st%nc_all
      st%big_g = sums(2) - st%zbar*sums(3)
      st%cross = sums(4) - st%zbar*sums(5)
   end subroutine precondition

   !> Sort the first n changes by column, then row: the threads recorded them in any
   !> order, and the sums over them, and so the answer, must not depend on it. A
   !> counting sort by column, then each column's few changes by row.
   subroutine sort_changes(st, n)
      type(cg_iteration), intent(inout) :: st
      integer, intent(in) :: n
      integer, allocatable :: start(:), by_column(:, :)
      real(dp), allocatable :: by_delta(:)
      integer :: q, jj, slot, key(2)
      real(dp) :: d
      allocate(start(st%nj + 1), by_column(2, n), by_delta(n))
      start = 0
      do q = 1, n
         start(st%changed(2, q) + 1) = start(st%changed(2, q) + 1) + 1
      end do
      start(1) = 1
      do jj = 2, st%nj + 1
         start(jj) = start(jj) + start(jj - 1)
      end do
      do q = 1, n
         slot = start(st%changed(2, q))
         start(st%changed(2, q)) = slot + 1
         by_column(:, slot) = st%changed(:, q)
         by_delta(slot) = st%delta(q)
      end do
      ! Rows within a column (stable insertion; a column holds few changes).
      do q = 2, n
         key = by_column(:, q)
         d = by_delta(q)
         jj = q - 1
         do while (jj >= 1)
            if (by_column(2, jj) /= key(2) .or. by_column(1, jj) <= key(1)) exit
            by_column(:, jj + 1) = by_column(:, jj)
            by_delta(jj + 1) = by_delta(jj)
            jj = jj - 1
         end do
         by_column(:, jj + 1) = key
         by_delta(jj + 1) = d
      end do
      st%changed(:, 1:n) = by_column
      st%delta(1:n) = by_delta
   end subroutine sort_changes

   !> Append pixel (i, j) to `list`, growing it by doubling.
   pure subroutine push_pixel(list, i, j)
      type(pixel_list), intent(inout) :: list
      integer, intent(in) :: i, j
      integer, allocatable :: grown(:, :)
      if (.not. allocated(list%ij)) allocate(list%ij(2, 1024))
      if (list%n == size(list%ij, 2)) then
         allocate(grown(2, 2*size(list%ij, 2)))
         grown(:, 1:list%n) = list%ij(:, 1:list%n)
         call move_alloc(grown, list%ij)
      end if
      list%n = list%n + 1
      list%ij(1, list%n) = i
      list%ij(2, list%n) = j
   end subroutine push_pixel
end module femcod_constrained_cg
