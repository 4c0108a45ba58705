!> Friction from the contact pressures: the thesis' first route to friction (section
!> 5.2.3, "the pressure distribution obtained from the contact model can be used together
!> with a pressure dependent surface shear model to estimate the friction coefficient").
!>
!> Each contact pixel carries the interfacial shear strength
!>     tau(p) = min(tau0 + alpha p, tau_max)                       (GPa)
!> at its pressure p = f/d^2 (f its force in nN, d the pixel in nm); the friction force is
!>     F_t = sum over the contact pixels of tau(p_i) d^2            (nN)
!> and the friction coefficient mu = F_t / F (F the load). tau0 is the junctions' shear
!> strength at zero pressure, alpha its pressure coefficient (Bowden and Tabor's
!> s = s0 + alpha p; Briscoe and Tabor measured alpha of 0.02 to 0.2 for polymer films).
!>
!> tau_max: with the plastic cap (--plastic) no junction is stronger in shear than the
!> softer material itself, k = H / (3 sqrt(3)): Tabor's H = 3 Y for the hardness and von
!> Mises' k = Y / sqrt(3) for the shear yield stress (Bowden-Tabor's mu = k / H = 0.19 for
!> fully plastic junctions of clean metals). Without the cap, tau is not bounded.
!>
!> The sum costs O(contacts) and no solve: the solvers evaluate it where they have the
!> forces (each history step, each requested state).
module femcod_shear_model
   use femcod_kinds, only: dp
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   implicit none
   private
   public :: shear_model, make_shear_model, friction_force, friction_coefficient, plastic_shear_strength

   !> The shear model of a run; `active` false: no friction is computed or written.
   type :: shear_model
      logical :: active = .false.
      !> Shear strength at zero pressure (GPa) and its pressure coefficient (1).
      real(dp) :: tau0 = 0, alpha = 0
      !> The largest shear strength (GPa; huge: none).
      real(dp) :: tau_max = huge(1.0_dp)
   end type shear_model

contains

   !> The shear model tau0 + alpha p (GPa, 1), capped at k = H/(3 sqrt 3) when `plastic`
   !> (H the hardness, GPa).
   pure function make_shear_model(tau0, alpha, plastic, hardness) result(model)
      real(dp), intent(in) :: tau0, alpha, hardness
      logical, intent(in) :: plastic
      type(shear_model) :: model
      model%active = .true.
      model%tau0 = tau0
      model%alpha = alpha
      if (plastic) model%tau_max = plastic_shear_strength(hardness)
   end function make_shear_model

   !> The shear yield stress k (GPa) of a material of hardness H (GPa): H = 3 Y (Tabor),
   !> k = Y / sqrt(3) (von Mises).
   pure real(dp) function plastic_shear_strength(hardness)
      real(dp), intent(in) :: hardness
      plastic_shear_strength = hardness/(3*sqrt(3.0_dp))
   end function plastic_shear_strength

   !> The friction force F_t (nN) of contact pixels with forces `force` (nN), pixel `pixel`
   !> (nm): sum of min(tau0 + alpha f/d^2, tau_max) d^2. Pixels below the cap contribute
   !> tau0 d^2 + alpha f each, summed as such (no division by d^2 and back).
   pure real(dp) function friction_force(model, force, pixel) result(total)
      type(shear_model), intent(in) :: model
      real(dp), intent(in) :: force(:), pixel
      real(dp) :: area, free_force
      integer :: k, free, capped
      total = 0
      if (.not. model%active) return
      area = pixel**2
      free = 0
      capped = 0
      free_force = 0
      do k = 1, size(force)
         if (model%tau0 + model%alpha*force(k)/area < model%tau_max) then
            free = free + 1
            free_force = free_force + force(k)
         else
            capped = capped + 1
         end if
      end do
      total = model%tau0*area*free + model%alpha*free_force
      if (capped > 0) total = total + model%tau_max*area*capped
   end function friction_force

   !> mu = F_t / F (1) of a state with `contacts` contact pixels; not a number where there
   !> is no contact or no positive load (a state unloaded off contact, whose load is
   !> round-off), where the ratio says nothing.
   pure real(dp) function friction_coefficient(friction, load, contacts)
      real(dp), intent(in) :: friction, load
      integer, intent(in) :: contacts
      friction_coefficient = ieee_value(friction, ieee_quiet_nan)
      if (load > 0 .and. contacts > 0) friction_coefficient = friction/load
   end function friction_coefficient
end module femcod_shear_model
