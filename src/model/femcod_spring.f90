!> SPRING: the axial voxel element of eqs. 4.7-4.9 (interface springs and penalty
!> contact springs). Lateral strains are zero, so for a voxel of area d**2 and height h
!>     k = E (1 - nu) / ((1 + nu)(1 - 2 nu)) * d**2 / h      (nN/nm, E in GPa, d, h in nm)
!> and the element matrix is k [[1, -1], [-1, 1]]. femcod takes the voxel height
!> h = d (a cubic voxel) for both kinds, with the deck's contact-element material, as
!> the thesis does ("the high stiffness defined for the rigid contact element is used
!> for both").
module femcod_spring
   use femcod_kinds, only: dp
   implicit none
   private
   public :: spring_stiffness, spring_element

contains

   !> Axial stiffness k of eq. 4.9 (nN/nm).
   pure real(dp) function spring_stiffness(young, poisson, pixel, height)
      real(dp), intent(in) :: young, poisson, pixel, height
      spring_stiffness = young*(1 - poisson)/((1 + poisson)*(1 - 2*poisson))*pixel**2/height
   end function spring_stiffness

   !> The 2 x 2 element matrix of eq. 4.8.
   pure function spring_element(k) result(element)
      real(dp), intent(in) :: k
      real(dp) :: element(2, 2)
      element = reshape([k, -k, -k, k], [2, 2])
   end function spring_element
end module femcod_spring
