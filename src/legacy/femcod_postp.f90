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
!>
!> Whether a candidate is in contact comes from IPSITU, the situation flags of the
!> first 5 MAXCONT gaps in IPSORT order; a pixel further down the order (reached only
!> by the search over every pixel) is looked up in IPCONT.
module femcod_postp
   use femcod_kinds, only: dp
   use femcod_condensed, only: gap_and_rate
   implicit none
   private
   public :: candidate_count, postp_search, in_contact_at

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

   !> Whether the pixel of gap rank `rank` (IPSORT order), pixel number `pixel`, is in
   !> contact: IPSITU(rank) within its 5 MAXCONT flags, else a look-up in IPCONT.
   pure logical function in_contact_at(rank, pixel, situ, contacts)
      integer, intent(in) :: rank, pixel, situ(:), contacts(:)
      if (rank <= size(situ)) then
         in_contact_at = situ(rank) == 1
      else
         in_contact_at = any(contacts == pixel)
      end if
   end function in_contact_at

   !> Search the first `ncand` pixels of `order` (IPSORT) not in contact for the next
   !> contact. Gaps are recomputed from the initial gaps g0 (MPGAPS), the total forces
   !> `ftot` (MPFORCE) and the approach `atot`, so no gap is ever stale. Returns the
   !> winning multiplier `lambda` (huge() when no candidate closes), the joining pixels
   !> with their ranks in `order`, and how many of them had already penetrated.
   pure subroutine postp_search(np, order, ncand, situ, contacts, g0, table, csum, ftot, atot, funit, delta, &
      total_load, tie_tolerance, lambda, joiners, joiner_ranks, njoin, nmissed)
      integer, intent(in) :: np, order(:), ncand, situ(:), contacts(:)
      real(dp), intent(in) :: g0(:), table(0:, 0:), csum, ftot(:), atot, funit(:), delta, total_load, tie_tolerance
      real(dp), intent(out) :: lambda
      integer, intent(out) :: joiners(:), joiner_ranks(:), njoin, nmissed
      real(dp), allocatable :: lam(:), gap(:)
      logical, allocatable :: candidate(:)
      integer, allocatable :: ic(:), jc(:)
      real(dp) :: rate, bound
      integer :: pos, p, ip, jp
      ! Heap arrays: the search over every pixel has NP**2 candidates.
      allocate(lam(ncand), gap(ncand), candidate(ncand))
      ic = (contacts - 1)/np + 1
      jc = contacts - (ic - 1)*np
      lambda = huge(1.0_dp)
      lam = huge(1.0_dp)
      do pos = 1, ncand
         p = order(pos)
         candidate(pos) = .not. in_contact_at(pos, p, situ, contacts)
         if (.not. candidate(pos)) cycle
         ip = (p - 1)/np + 1
         jp = p - (ip - 1)*np
         call gap_and_rate(g0(p), atot, delta, csum, table, ip, jp, ic, jc, ftot, funit, gap(pos), rate)
         if (gap(pos) <= 0) then
            lam(pos) = min(0.0_dp, gap(pos))
         else if (rate > 0) then
            lam(pos) = gap(pos)/rate
         end if
         lambda = min(lambda, lam(pos))
      end do
      njoin = 0
      nmissed = 0
      if (lambda == huge(1.0_dp)) return
      bound = max(lambda, 0.0_dp) + tie_tolerance*(total_load + max(lambda, 0.0_dp))
      do pos = 1, ncand
         if (.not. candidate(pos)) cycle
         if (lam(pos) <= bound) then
            njoin = njoin + 1
            if (njoin <= size(joiners)) then
               joiners(njoin) = order(pos)
               joiner_ranks(njoin) = pos
            end if
            if (gap(pos) < -tie_tolerance*atot) nmissed = nmissed + 1
         end if
      end do
      lambda = max(lambda, 0.0_dp)
   end subroutine postp_search
end module femcod_postp
