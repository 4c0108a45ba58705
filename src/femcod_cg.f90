!> Fixed-load solver (`--solver cg`): at each requested load, the contact forces of the
!> complementarity problem
!>     F >= 0,  g = g0 - A + c (I * F) + s F >= 0,  F g = 0,  sum F = P
!> on the non-padded NP x NP grid (the same composite model as the other solvers: one
!> compliance c = c1 + c2 with the exact Love kernel I, the springs' s = 3/k on the
!> diagonal, one composite gap g0), by the constrained conjugate gradients of Polonsky and
!> Keer (Wear 231, 1999, 206-219). I * F is a zero-padded (2NP)^2 FFT convolution (FFTW,
!> plans made once). Each load starts from the previous load's forces (warm start).
!>
!> Stopping rule: the relative complementarity residual
!>     r = max( max over contacts |g| , max over the rest max(-g, 0) ) / (max g0 - min g0)
!> (the largest gap violation in units of the height range) below `tol` (default 1e-8),
!> with the load balanced to round-off by construction. The residuals reached are
!> returned: max penetration (nm), largest |gap| on contact (nm), load error, r.
module femcod_cg
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_deck, only: deck_type
   use femcod_scene, only: initial_gaps
   use femcod_boussinesq, only: offset_table, surface_compliance
   use femcod_spring, only: spring_stiffness
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_free
   use femcod_contact_result, only: contact_result, contact_options, append_step, STOP_LOADS
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: solve_cg, cg_residuals

   !> What the CG solver reached at one load.
   type :: cg_residuals
      integer :: iterations = 0
      real(dp) :: penetration = 0, contact_gap = 0, load_error = 0, residual = 0
   end type cg_residuals

contains

   !> Solve at every requested load (ascending order of computation; results in the
   !> order given). `report(k)` holds the residuals at load k.
   subroutine solve_cg(deck, options, tol, max_iterations, res, report, status)
      type(deck_type), intent(in) :: deck
      type(contact_options), intent(in) :: options
      real(dp), intent(in) :: tol
      integer, intent(in) :: max_iterations
      type(contact_result), intent(out) :: res
      type(cg_residuals), allocatable, intent(out) :: report(:)
      type(status_type), intent(inout) :: status
      type(love_convolution) :: conv
      real(dp), allocatable :: table(:, :), g0(:, :), p(:, :), t(:, :), u(:, :), r(:, :), g(:, :), pold(:, :)
      integer, allocatable :: order(:)
      real(dp) :: c, s, load, scale, tstart, t0, t1
      integer :: np, k, kk, m, i, j, nc
      call wall_clock(tstart)
      np = deck%np
      m = size(options%loads)
      allocate(report(m), res%states(m))
      res%states%load = options%loads
      if (m == 0) then
         call set_error(status, STATUS_NUMERICAL, "cg: --solver cg needs --loads")
         return
      end if
      allocate(table(0:np - 1, 0:np - 1))
      table = offset_table(np)
      c = surface_compliance(deck%young(1), deck%poisson(1), deck%pixel) + &
         surface_compliance(deck%young(2), deck%poisson(2), deck%pixel)
      s = 3/spring_stiffness(deck%young(3), deck%poisson(3), deck%pixel, deck%pixel)
      g0 = transpose(reshape(initial_gaps(deck%lower, deck%upper), [np, np]))
      scale = max(maxval(g0) - minval(g0), tiny(1.0_dp))
      call convolution_setup(conv, table)
      allocate(p(np, np), t(np, np), u(np, np), r(np, np), g(np, np), pold(np, np))
      ! Ascending loads, each warm-started from the last.
      allocate(order(m))
      order = [(k, k = 1, m)]
      do k = 2, m
         kk = k
         do while (kk > 1)
            if (options%loads(order(kk - 1)) <= options%loads(order(kk))) exit
            order([kk - 1, kk]) = order([kk, kk - 1])
            kk = kk - 1
         end do
      end do
      p = 0
      do kk = 1, m
         k = order(kk)
         load = options%loads(k)
         call wall_clock(t0)
         call one_load(load, report(k))
         if (status%code /= 0) exit
         call wall_clock(t1)
         ! The state at this load.
         associate(st => res%states(k))
            st%reached = .true.
            st%contacts = count(p > 0)
            st%max_pressure = maxval(p)/deck%pixel**2
            st%n_above_hardness = count(p/deck%pixel**2 > options%hardness)
            allocate(st%i(st%contacts), st%j(st%contacts), st%force(st%contacts))
            nc = 0
            do i = 1, np
               do j = 1, np
                  if (p(i, j) > 0) then
                     nc = nc + 1
                     st%i(nc) = i
                     st%j(nc) = j
                     st%force(nc) = p(i, j)
                  end if
               end do
            end do
            call append_step(res, st%contacts, st%n_above_hardness, load, st%approach, t1 - t0)
            if (load == maxval(options%loads)) then
               res%contact_i = st%i
               res%contact_j = st%j
               res%contact_step = [(kk, i = 1, st%contacts)]
               res%contact_force = st%force
               res%reported_load = load
            end if
         end associate
      end do
      call convolution_free(conv)
      res%stop_reason = STOP_LOADS
      call wall_clock(t1)
      res%wall_seconds = t1 - tstart
   contains
      !> Polonsky-Keer constrained CG at total load P, from the current p.
      subroutine one_load(total_load, rep)
         real(dp), intent(in) :: total_load
         type(cg_residuals), intent(out) :: rep
         real(dp) :: gbar, big_g, big_g_old, tau, rbar, num, den, approach, rsum, beta
         logical :: restart
         integer :: it, nc
         if (total_load <= 0) then
            p = 0
            res%states(k)%approach = -minval(g0)
            rep%residual = 0
            return
         end if
         if (sum(p) <= 0) then
            ! Start: the load spread over the pixels of the smallest gaps' tenth.
            where (g0 <= minval(g0) + 0.1_dp*scale)
               p = 1
            elsewhere
               p = 0
            end where
         end if
         p = p*(total_load/sum(p))
         big_g_old = 1
         restart = .true.
         t = 0
         do it = 1, max_iterations
            rep%iterations = it
            call convolution_apply(conv, p, u)
            g = g0 + c*u + s*p
            nc = count(p > 0)
            if (nc == 0) exit
            gbar = sum(g, mask=p > 0)/nc
            approach = gbar
            g = g - gbar
            big_g = sum(g**2, mask=p > 0)
            if (restart .or. .not. big_g_old > 0) then
               beta = 0
            else
               beta = big_g/big_g_old
            end if
            where (p > 0)
               t = g + beta*t
            elsewhere
               t = 0
            end where
            big_g_old = big_g
            call convolution_apply(conv, t, r)
            r = c*r + s*t
            rbar = sum(r, mask=p > 0)/nc
            r = r - rbar
            num = sum(g*t, mask=p > 0)
            den = sum(r*t, mask=p > 0)
            if (.not. abs(den) > 0) exit
            tau = num/den
            pold = p
            where (p > 0) p = p - tau*t
            where (p < 0) p = 0
            ! Overlapping pixels enter the contact.
            restart = any(pold <= 0 .and. g < 0)
            where (pold <= 0 .and. g < 0) p = p - tau*g
            rsum = sum(p)
            if (.not. rsum > 0) then
               call set_error(status, STATUS_NUMERICAL, "cg: all forces vanished")
               return
            end if
            p = p*(total_load/rsum)
            ! Residuals of the current iterate (gaps from the last convolution).
            rep%contact_gap = maxval(abs(g), mask=pold > 0)
            rep%penetration = max(0.0_dp, -minval(g, mask=pold <= 0))
            rep%residual = max(rep%contact_gap, rep%penetration)/scale
            if (rep%residual < tol .and. it > 1) exit
         end do
         ! Final residuals from a fresh convolution of the final forces.
         call convolution_apply(conv, p, u)
         g = g0 + c*u + s*p
         nc = max(count(p > 0), 1)
         approach = sum(g, mask=p > 0)/nc
         g = g - approach
         rep%contact_gap = maxval(abs(g), mask=p > 0)
         rep%penetration = max(0.0_dp, -minval(g, mask=p <= 0))
         rep%residual = max(rep%contact_gap, rep%penetration)/scale
         rep%load_error = abs(sum(p) - total_load)/total_load
         ! Approach measured as in the other solvers: from first touch (gap 0 at the
         ! highest pair of voxels).
         res%states(k)%approach = approach
         res%states(k)%iterations = rep%iterations
         res%states(k)%residual = rep%residual
         res%states(k)%penetration = rep%penetration
         res%states(k)%contact_gap = rep%contact_gap
         res%states(k)%load_error = rep%load_error
      end subroutine one_load
   end subroutine solve_cg
end module femcod_cg
