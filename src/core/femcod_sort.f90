!> Stable merge sort with index permutation (Appendix B orders the gaps with a
!> merge sort and stores the pixel numbers, ascending gap, in IPSORT).
module femcod_sort
   use femcod_kinds, only: dp
   implicit none
   private
   public :: merge_sort_index

contains

   !> `order` receives the permutation that sorts `values` ascending; equal values
   !> keep their original (row-wise pixel) order. O(n log n) time, n extra integers.
   pure subroutine merge_sort_index(values, order)
      real(dp), intent(in) :: values(:)
      integer, intent(out) :: order(:)
      integer, allocatable :: buffer(:)
      integer :: n, width, lo, mid, hi, i, j, k
      n = size(values)
      do i = 1, n
         order(i) = i
      end do
      allocate(buffer(n))
      width = 1
      do while (width < n)
         lo = 1
         do while (lo <= n - width)
            mid = lo + width - 1
            hi = min(lo + 2*width - 1, n)
            if (values(order(mid)) > values(order(mid + 1))) then
               i = lo
               j = mid + 1
               k = lo
               do while (i <= mid .and. j <= hi)
                  ! "<=" keeps the left (earlier) element first on ties: stability.
                  if (values(order(i)) <= values(order(j))) then
                     buffer(k) = order(i)
                     i = i + 1
                  else
                     buffer(k) = order(j)
                     j = j + 1
                  end if
                  k = k + 1
               end do
               buffer(k:k + mid - i) = order(i:mid)
               k = k + mid - i + 1
               buffer(k:k + hi - j) = order(j:hi)
               order(lo:hi) = buffer(lo:hi)
            end if
            lo = lo + 2*width
         end do
         width = 2*width
      end do
   end subroutine merge_sort_index
end module femcod_sort
