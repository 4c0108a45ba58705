!> Contact patches (model/femcod_patches) on a map counted by hand: 4- and 8-connected,
!> on a free grid and on a periodic cell, each patch's area and perimeter.
module test_patches
   use femcod_kinds, only: dp
   use femcod_patches, only: contact_patches, find_patches, perimeter_area_fit
   use testdrive, only: new_unittest, unittest_type, error_type, check
   implicit none
   private
   public :: collect_patches

   !> The map (1: contact), row i of the text is row i of the grid:
   !>   1 1 0 0 0 0 0 1     A = (1,1) (1,2) (2,1);  B = (1,8) (2,8)
   !>   1 0 0 0 0 0 0 1     C = (3,4), D = (4,3), E = (4,5), F = (5,4): a diamond whose
   !>   0 0 0 1 0 0 0 0         pixels touch by their corners only
   !>   0 0 1 0 1 0 0 0     G = the 2 x 2 block (7:8, 6:7);  H = (8,1)
   !>   0 0 0 1 0 0 0 0
   !>   0 0 0 0 0 0 0 0
   !>   0 0 0 0 0 1 1 0
   !>   1 0 0 0 0 1 1 0
   character(len=*), parameter :: MAP(8) = [character(len=8) :: "11000001", "10000001", "00010000", &
      "00101000", "00010000", "00000000", "00000110", "10000110"]

contains

   subroutine collect_patches(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("a map counted by hand, free grid: 8 patches 4-connected, 5 8-connected", test_free), &
         new_unittest("the same map as a periodic cell: 6 and 2 patches across its edges", test_periodic), &
         new_unittest("no contact, full contact, and the perimeter-area fit of squares", test_edge_cases) &
         ]
   end subroutine collect_patches

   subroutine map_pixels(i, j)
      integer, allocatable, intent(out) :: i(:), j(:)
      integer :: r, c
      allocate(i(0), j(0))
      do c = 1, 8
         do r = 1, 8
            if (MAP(r)(c:c) == "1") then
               i = [i, r]
               j = [j, c]
            end if
         end do
      end do
   end subroutine map_pixels

   !> Free grid. 4-connected, labelled in the order of each patch's first pixel in column
   !> order: A, H, D, C, F, E, G, B with areas 3 1 1 1 1 1 4 2; perimeters (sides facing
   !> no contact or the grid's edge) A: (1,1) 2 + (1,2) 3 + (2,1) 3 = 8, single pixels 4,
   !> G 8, B: (1,8) 3 + (2,8) 3 = 6. 8-connected: A, H, the diamond CDEF (4 pixels,
   !> 16 sides), G, B.
   subroutine test_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_patches) :: p
      integer, allocatable :: i(:), j(:)
      call map_pixels(i, j)
      call find_patches(8, i, j, .false., p)
      call check(error, p%count4 == 8 .and. p%count8 == 5, "counts 8 and 5")
      if (allocated(error)) return
      call check(error, all(p%area4 == [3, 1, 1, 1, 1, 1, 4, 2]) .and. all(p%perimeter4 == [8, 4, 4, 4, 4, 4, 8, 6]), &
         "4-connected areas and perimeters")
      if (allocated(error)) return
      call check(error, all(p%area8 == [3, 1, 4, 4, 2]) .and. all(p%perimeter8 == [8, 4, 16, 8, 6]), &
         "8-connected areas and perimeters")
   end subroutine test_free

   !> Periodic cell: column 8 meets column 1 and row 8 row 1. 4-connected: A, B and H
   !> join (6 pixels; perimeter (1,1) 0 + (1,2) 3 + (2,1) 2 + (1,8) 2 + (2,8) 2 + (8,1) 3
   !> = 12), the diamond's four pixels stay apart, G stays (8): 6 patches. 8-connected:
   !> G's corner (8,7) touches (1,8) across both edges, so ABHG is one patch (10 pixels,
   !> 20 sides) and the diamond the other: 2.
   subroutine test_periodic(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_patches) :: p
      integer, allocatable :: i(:), j(:)
      call map_pixels(i, j)
      call find_patches(8, i, j, .true., p)
      call check(error, p%count4 == 6 .and. p%count8 == 2, "counts 6 and 2")
      if (allocated(error)) return
      call check(error, all(p%area4 == [6, 1, 1, 1, 1, 4]) .and. all(p%perimeter4 == [12, 4, 4, 4, 4, 8]), &
         "4-connected areas and perimeters")
      if (allocated(error)) return
      call check(error, all(p%area8 == [10, 4]) .and. all(p%perimeter8 == [20, 16]), &
         "8-connected areas and perimeters")
   end subroutine test_periodic

   !> No contact: no patch. Every pixel: one patch of NP^2 pixels, perimeter 4 NP on a
   !> free grid and 0 on a periodic cell. Squares of side s have area s^2 and perimeter
   !> 4 s: the fit gives the exponent 1/2 and the prefactor 4.
   subroutine test_edge_cases(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_patches) :: p
      integer :: i(25), j(25), k
      real(dp) :: exponent, prefactor
      call find_patches(5, [integer :: ], [integer :: ], .false., p)
      call check(error, p%count4 == 0 .and. p%count8 == 0 .and. size(p%area4) == 0, "no contact")
      if (allocated(error)) return
      i = [((k - 1)/5 + 1, k = 1, 25)]
      j = [(modulo(k - 1, 5) + 1, k = 1, 25)]
      call find_patches(5, i, j, .false., p)
      call check(error, p%count4 == 1 .and. p%area4(1) == 25 .and. p%perimeter4(1) == 20, "full contact, free")
      if (allocated(error)) return
      call find_patches(5, i, j, .true., p)
      call check(error, p%count8 == 1 .and. p%perimeter8(1) == 0, "full contact, periodic")
      if (allocated(error)) return
      call perimeter_area_fit([1, 4, 9, 16], [4, 8, 12, 16], exponent, prefactor)
      call check(error, abs(exponent - 0.5_dp) < 1e-12_dp .and. abs(prefactor - 4) < 1e-12_dp, "squares: 4 A^(1/2)")
   end subroutine test_edge_cases
end module test_patches
