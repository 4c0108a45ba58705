!> The contact problem condensed to the contact degrees of freedom.
!>
!> For an active set of contact pixels C with total forces F (nN, compression
!> positive) and the approach A of the two handles (nm), the gap left at pixel p is
!>     gap(p) = g0(p) - A + c * sum_k I(p - k) F(k)        (c = c1 + c2, nm/nN)
!> and at a contact the springs in series (two interface springs and the penalty
!> spring, compliance s each 1/k) take up the rest: gap(k) + s_total F(k) = 0 ... with
!> the sign convention that a contact's gap is closed. The exact state for an active
!> set at total load P therefore solves the bordered symmetric system
!>     [ c I_CC + s_total Id   -1 ] [F]   [-g0_C]
!>     [        -1'             0 ] [A] = [ -P  ]
!> which femcod solves with LAPACK (dsysv). It is the reference the legacy history is
!> checked against, and the correction applied when the final check finds a missed
!> contact.
module femcod_condensed
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use, intrinsic :: iso_c_binding, only: c_int
   use femcod_lapack, only: dsysv, blas_set_threads
   implicit none
   private
   public :: solve_active_set, gap_at, gap_and_rate

contains

   !> Gap (nm) at pixel (ip, jp) for contacts at (ic, jc) with forces f (nN).
   pure real(dp) function gap_at(g0, approach, csum, table, ip, jp, ic, jc, f)
      real(dp), intent(in) :: g0, approach, csum, table(0:, 0:), f(:)
      integer, intent(in) :: ip, jp, ic(:), jc(:)
      integer :: k
      real(dp) :: s
      s = 0
      do k = 1, size(f)
         s = s + table(abs(ip - ic(k)), abs(jp - jc(k)))*f(k)
      end do
      gap_at = g0 - approach + csum*s
   end function gap_at

   !> Current gap (nm) of pixel (ip, jp) under total forces `ftot` and approach `atot`,
   !> and its closing rate (nm/nN) under the unit-load forces `funit` and approach rate
   !> `delta`: gap = g0 - atot + c sum I ftot, rate = delta - c sum I funit (one pass).
   pure subroutine gap_and_rate(g0, atot, delta, csum, table, ip, jp, ic, jc, ftot, funit, gap, rate)
      real(dp), intent(in) :: g0, atot, delta, csum, table(0:, 0:), ftot(:), funit(:)
      integer, intent(in) :: ip, jp, ic(:), jc(:)
      real(dp), intent(out) :: gap, rate
      integer :: k
      real(dp) :: s_tot, s_unit, t
      s_tot = 0
      s_unit = 0
      do k = 1, size(ftot)
         t = table(abs(ip - ic(k)), abs(jp - jc(k)))
         s_tot = s_tot + t*ftot(k)
         s_unit = s_unit + t*funit(k)
      end do
      gap = g0 - atot + csum*s_tot
      rate = delta - csum*s_unit
   end subroutine gap_and_rate

   !> Exact forces and approach for the active set (ic, jc) at total load `load`.
   subroutine solve_active_set(ic, jc, g0, csum, spring_compliance, table, load, forces, approach, status)
      integer, intent(in) :: ic(:), jc(:)
      real(dp), intent(in) :: g0(:), csum, spring_compliance, table(0:, 0:), load
      real(dp), intent(out) :: forces(:), approach
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: a(:, :), b(:, :), work(:)
      integer, allocatable :: ipiv(:)
      integer :: n, k, l, info
      integer(c_int) :: before
      n = size(ic)
      allocate(a(n + 1, n + 1), b(n + 1, 1), ipiv(n + 1), work(64*(n + 1)))
      do l = 1, n
         do k = 1, n
            a(k, l) = csum*table(abs(ic(k) - ic(l)), abs(jc(k) - jc(l)))
         end do
         a(l, l) = a(l, l) + spring_compliance
         a(l, n + 1) = -1
         a(n + 1, l) = -1
      end do
      a(n + 1, n + 1) = 0
      b(1:n, 1) = -g0
      b(n + 1, 1) = -load
      ! On one OpenBLAS thread: the same bits whatever the thread count.
      before = blas_set_threads(1_c_int)
      call dsysv("U", n + 1, 1, a, n + 1, ipiv, b, n + 1, work, size(work), info)
      if (before > 0) before = blas_set_threads(before)
      if (info /= 0) then
         call set_error(status, STATUS_NUMERICAL, "active-set solve: singular system")
         forces = 0
         approach = 0
         return
      end if
      forces = b(1:n, 1)
      approach = b(n + 1, 1)
   end subroutine solve_active_set
end module femcod_condensed
