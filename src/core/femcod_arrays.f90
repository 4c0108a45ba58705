!> Allocatable arrays that grow: one routine for every list the code appends to (the run's
!> history, the summits, the multiscale scales, a height file's values).
module femcod_arrays
   use femcod_kinds, only: dp
   implicit none
   private
   public :: grow

   !> grow(a, n): `a` with room for `n` values (n at least its size), its values kept at
   !> its head and the rest undefined.
   interface grow
      module procedure grow_integers, grow_reals
   end interface grow

contains

   pure subroutine grow_integers(a, n)
      integer, allocatable, intent(inout) :: a(:)
      integer, intent(in) :: n
      integer, allocatable :: wider(:)
      allocate(wider(n))
      wider(1:size(a)) = a
      call move_alloc(wider, a)
   end subroutine grow_integers

   pure subroutine grow_reals(a, n)
      real(dp), allocatable, intent(inout) :: a(:)
      integer, intent(in) :: n
      real(dp), allocatable :: wider(:)
      allocate(wider(n))
      wider(1:size(a)) = a
      call move_alloc(wider, a)
   end subroutine grow_reals
end module femcod_arrays
