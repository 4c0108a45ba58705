!> A binary min-heap of (key, item) pairs, used by the event-exact solver to find the
!> pixels whose lower bound on the gap says they might close next.
module femcod_heap
   use femcod_kinds, only: dp
   implicit none
   private
   public :: min_heap, heap_build, heap_push, heap_pop, heap_top_key

   type :: min_heap
      integer :: size = 0
      real(dp), allocatable :: key(:)
      integer, allocatable :: item(:)
   end type min_heap

contains

   !> Build a heap from all pairs at once (O(n)); `capacity` >= size(keys).
   pure subroutine heap_build(heap, keys, items, capacity)
      type(min_heap), intent(out) :: heap
      real(dp), intent(in) :: keys(:)
      integer, intent(in) :: items(:), capacity
      integer :: k
      allocate(heap%key(capacity), heap%item(capacity))
      heap%size = size(keys)
      heap%key(1:heap%size) = keys
      heap%item(1:heap%size) = items
      do k = heap%size/2, 1, -1
         call sift_down(heap, k)
      end do
   end subroutine heap_build

   pure subroutine heap_push(heap, key, item)
      type(min_heap), intent(inout) :: heap
      real(dp), intent(in) :: key
      integer, intent(in) :: item
      integer :: k, parent
      real(dp) :: kt
      integer :: it
      heap%size = heap%size + 1
      k = heap%size
      heap%key(k) = key
      heap%item(k) = item
      do while (k > 1)
         parent = k/2
         if (heap%key(parent) <= heap%key(k)) exit
         kt = heap%key(parent); heap%key(parent) = heap%key(k); heap%key(k) = kt
         it = heap%item(parent); heap%item(parent) = heap%item(k); heap%item(k) = it
         k = parent
      end do
   end subroutine heap_push

   pure subroutine heap_pop(heap, key, item)
      type(min_heap), intent(inout) :: heap
      real(dp), intent(out) :: key
      integer, intent(out) :: item
      key = heap%key(1)
      item = heap%item(1)
      heap%key(1) = heap%key(heap%size)
      heap%item(1) = heap%item(heap%size)
      heap%size = heap%size - 1
      if (heap%size > 1) call sift_down(heap, 1)
   end subroutine heap_pop

   !> Smallest key, +huge when empty.
   pure real(dp) function heap_top_key(heap)
      type(min_heap), intent(in) :: heap
      heap_top_key = huge(1.0_dp)
      if (heap%size > 0) heap_top_key = heap%key(1)
   end function heap_top_key

   pure subroutine sift_down(heap, start)
      type(min_heap), intent(inout) :: heap
      integer, intent(in) :: start
      integer :: k, child, it
      real(dp) :: kt
      k = start
      do
         child = 2*k
         if (child > heap%size) exit
         if (child < heap%size) then
            if (heap%key(child + 1) < heap%key(child)) child = child + 1
         end if
         if (heap%key(k) <= heap%key(child)) exit
         kt = heap%key(child); heap%key(child) = heap%key(k); heap%key(k) = kt
         it = heap%item(child); heap%item(child) = heap%item(k); heap%item(k) = it
         k = child
      end do
   end subroutine sift_down
end module femcod_heap
