!> POSTP of Appendix B: the candidate search for the next contact.
!>
!> The candidate list is the `candidate_count(n)` pixels with the smallest initial
!> gaps (IPSORT order): 100 until the 40th contact, then 2.5 n (Appendix B). For each
!> candidate not yet in contact, the current gap and its closing rate under the unit
!> load give the load multiplier that closes it,
!>     lambda(p) = gap(p) / (delta - c sum_k I(p-k) f(k)),
!> (delta: approach per nN, f: contact forces per nN). The smallest wins; every
!> candidate within `tie_tolerance` times the total load of it joins in the same step.
!> A candidate whose gap is already negative was missed earlier: it joins at once
!> (lambda = 0), as the thesis corrects late-found contacts.
module femcod_postp
   use femcod_kinds, only: dp
   use femcod_condensed, only: gap_and_rate
   implicit none
   private
   public :: candidate_count, postp_search

contains

   !> Candidate list size for n contacts (Appendix B: 100, then 2.5 n after the 40th).
   pure integer function candidate_count(ncont, npixels)
      integer, intent(in) :: ncont, npixels
      if (ncont <= 40) then
         candidate_count = 100
      else
         candidate_count = ceiling(2.5_dp*ncont)
      end if
      candidate_count = min(candidate_count, npixels)
   end function candidate_count

   !> Search the first `ncand` pixels of `order` (not in contact) for the next contact.
   !> Gaps are recomputed from the total forces `ftot` and approach `atot`, so no gap is
   !> ever stale. Returns the winning multiplier `lambda` (huge() when no candidate
   !> closes), the joining pixels and how many of them had already penetrated.
   pure subroutine postp_search(np, order, ncand, in_contact, g0, table, csum, ic, jc, ftot, atot, funit, delta, &
      total_load, tie_tolerance, lambda, joiners, njoin, nmissed, gaps)
      integer, intent(in) :: np, order(:), ncand, ic(:), jc(:)
      logical, intent(in) :: in_contact(:)
      real(dp), intent(in) :: g0(:), table(0:, 0:), csum, ftot(:), atot, funit(:), delta, total_load, tie_tolerance
      real(dp), intent(out) :: lambda
      integer, intent(out) :: joiners(:), njoin, nmissed
      real(dp), intent(inout) :: gaps(:)
      real(dp) :: lam(ncand), rate, bound
      integer :: pos, p, ip, jp
      lambda = huge(1.0_dp)
      lam = huge(1.0_dp)
      do pos = 1, ncand
         p = order(pos)
         if (in_contact(p)) cycle
         ip = (p - 1)/np + 1
         jp = p - (ip - 1)*np
         call gap_and_rate(g0(p), atot, delta, csum, table, ip, jp, ic, jc, ftot, funit, gaps(p), rate)
         if (gaps(p) <= 0) then
            lam(pos) = min(0.0_dp, gaps(p))
         else if (rate > 0) then
            lam(pos) = gaps(p)/rate
         end if
         lambda = min(lambda, lam(pos))
      end do
      njoin = 0
      nmissed = 0
      if (lambda == huge(1.0_dp)) return
      bound = max(lambda, 0.0_dp) + tie_tolerance*(total_load + max(lambda, 0.0_dp))
      do pos = 1, ncand
         p = order(pos)
         if (in_contact(p)) cycle
         if (lam(pos) <= bound) then
            njoin = njoin + 1
            if (njoin <= size(joiners)) joiners(njoin) = p
            if (gaps(p) < -tie_tolerance*atot) nmissed = nmissed + 1
         end if
      end do
      lambda = max(lambda, 0.0_dp)
   end subroutine postp_search
end module femcod_postp
