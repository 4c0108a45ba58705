!> The summary `femcod run` prints on standard output after a deck: the problem, the
!> states (load, approach, area, pressures, patches, friction, the tangential step), the
!> solver's own lines and checks.
module femcod_run_summary
   use, intrinsic :: iso_fortran_env, only: output_unit
   use femcod_kinds, only: dp
   use femcod_strings, only: string_type, sig_str, int_str, format_real
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result, state_values, stop_reason_text, cg_work, &
      cg_state_diagnostics
   use femcod_solver_options, only: contact_options, SOLVER_CG, LAW_HARD_WALL, solver_name
   use femcod_shear_model, only: friction_coefficient
   use femcod_solver, only: report_lines, report_line
   use femcod_maps, only: state_maps
   use femcod_patches, only: contact_patches, perimeter_area_fit
   implicit none
   private
   public :: print_summary, state_summary_lines

contains

   !> The summary on standard output: the scene, the steps, the states at the requested
   !> loads, the wall time, then what the solver left out and checked.
   subroutine print_summary(deck_path, prefix, problem, options, res, maps)
      character(len=*), intent(in) :: deck_path, prefix
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(contact_result), intent(in) :: res
      type(state_maps), intent(in) :: maps(:)
      type(report_line), allocatable :: lines(:)
      type(string_type), allocatable :: lines_of_state(:)
      type(cg_state_diagnostics) :: work
      integer :: k, m, last
      last = res%nsteps
      if (deck_path /= "") then
         write(output_unit, '(a)') "femcod run "//deck_path//" (solver "//solver_name(options%solver)//")"
      else
         ! Height files: the scene's label names them (femcod run --lower FILE ...).
         write(output_unit, '(a)') problem%label//" (solver "//solver_name(options%solver)//")"
      end if
      write(output_unit, '(a)') "  scene     : "//problem%label
      write(output_unit, '(a)') "              NP = "//int_str(problem%np)//", d = "//format_real(problem%pixel)// &
         " nm, E = "//sig_str(problem%young(1), 4)//" / "//sig_str(problem%young(2), 4)//" / "// &
         sig_str(problem%young(3), 4)//" GPa (lower / upper / contact)"
      if (options%solver == SOLVER_CG) then
         write(output_unit, '(a)') "  loads     : "//int_str(count(res%states%reached))//" of "// &
            int_str(size(res%states))//" solved"
      else
         write(output_unit, '(a)') "  steps     : "//int_str(last)//", stopped: "//stop_reason_text(res%stop_reason)
         if (last > 0) then
            write(output_unit, '(a)') "  last step : "//int_str(res%step_contacts(last))//" contacts up to load "// &
               sig_str(res%step_load(last), 6)//" nN (where the next contact closes), approach "// &
               sig_str(res%step_approach(last), 6)//" nm"
         end if
      end if
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         work = cg_work(res, k)
         lines_of_state = state_summary_lines(res%states%state_values, k, problem%pixel, options, &
            work%approach_bound, patch_detail(maps(k)%patches))
         do m = 1, size(lines_of_state)
            write(output_unit, '(a)') lines_of_state(m)%s
         end do
      end do
      if (options%adhesion /= LAW_HARD_WALL) write(output_unit, '(a)') "  adhesion  : least load "// &
         sig_str(minval(res%states%load, mask=res%states%reached), 6)//" nN over the approaches (the pull-off force "// &
         "where they pass it)"
      if (options%solver == SOLVER_CG) then
         write(output_unit, '(a)') "  wall time : "//sig_str(res%wall_seconds, 3)//" s"
      else
         write(output_unit, '(a)') "  wall time : "//sig_str(res%wall_seconds, 3)//" s in total, "// &
            sig_str(res%wall_seconds/max(last, 1), 3)//" s per step"
      end if
      write(output_unit, '(a)') "  written   : "//prefix//".h5, .xdmf, .summary.json, .history.csv, .contacts.csv, "// &
         ".load_approach.svg, .area_load.svg"//trim(merge(", .loads.csv, .pressure_<k>.svg, .gap_<k>.svg", &
         repeat(" ", 45), size(res%states) > 0))
      ! The solver's own account last.
      lines = report_lines(problem, options, res)
      do k = 1, size(lines)
         write(output_unit, '(a)') "  "//lines(k)%label//repeat(" ", max(0, 10 - len(lines(k)%label)))//": "// &
            lines(k)%text
      end do
   end subroutine print_summary

   !> A reached state's lines in the summary (`femcod run`'s and femcod-mpi's): the load,
   !> approach (with its bound where `bound` >= 0), contacts, area and largest pressure;
   !> the patches (`detail`: what the program knows beyond their counts); and where the
   !> run has them the plastic pixels, the tangential step, the shear model's friction,
   !> the adhesion (with a jump since state k - 1).
   function state_summary_lines(states, k, pixel, options, bound, detail) result(lines)
      type(state_values), intent(in) :: states(:)
      integer, intent(in) :: k
      real(dp), intent(in) :: pixel, bound
      type(contact_options), intent(in) :: options
      character(len=*), intent(in) :: detail
      type(string_type), allocatable :: lines(:)
      character(len=*), parameter :: indent = "              "
      associate(s => states(k))
         lines = [string_type("  at load   : "//sig_str(s%load, 6)//" nN: approach "//sig_str(s%approach, 6)//" nm"// &
            trim(bound_text(bound))//", "//int_str(s%contacts)//" contacts ("//sig_str(s%contacts*pixel**2, 4)// &
            " nm^2), max pressure "//sig_str(s%max_pressure, 4)//" GPa"), &
            string_type(indent//"patches "//int_str(s%patches_4)//" (4-connected), "//int_str(s%patches_8)// &
            " (8-connected)"//detail)]
         if (options%plastic) lines = [lines, string_type(indent//int_str(s%n_plastic)//" of them plastic (at the "// &
            "hardness "//sig_str(options%hardness, 4)//" GPa), plastic volume "//sig_str(s%plastic_volume, 4)//" nm^3")]
         if (options%tangential) lines = [lines, string_type(indent//tangential_text(s, pixel))]
         if (options%shear) lines = [lines, string_type(indent//"friction "//sig_str(s%friction, 6)//" nN, coefficient "// &
            sig_str(friction_coefficient(s%friction, s%load, s%contacts), 6)//" (shear model)")]
         if (options%adhesion /= LAW_HARD_WALL) then
            lines = [lines, string_type(indent//int_str(s%attractive)//" pixels off contact within the range ("// &
               sig_str(s%attractive*pixel**2, 4)//" nm^2), load off contact "//sig_str(s%attractive_load, 4)// &
               " nN, mean gap "//sig_str(s%mean_gap, 4)//" nm")]
            if (s%jump /= 0 .and. k > 1) lines = [lines, string_type(indent// &
               trim(merge("contact appears ", "contact vanishes", s%jump > 0))//" since the approach "// &
               sig_str(states(k - 1)%approach, 6)//" nm ("//int_str(states(k - 1)%contacts)//" -> "// &
               int_str(s%contacts)//" contact pixels, load "//sig_str(states(k - 1)%load, 4)//" -> "// &
               sig_str(s%load, 4)//" nN)")]
         end if
      end associate
   end function state_summary_lines

   !> ", the largest N pixels, perimeter ~ area^e": the patches beyond their counts.
   function patch_detail(patches) result(text)
      type(contact_patches), intent(in) :: patches
      character(len=:), allocatable :: text
      real(dp) :: exponent, prefactor
      call perimeter_area_fit(patches%area4, patches%perimeter4, exponent, prefactor)
      text = ", the largest "//int_str(maxval([0, patches%area8]))//" pixels"
      if (exponent == exponent) text = text//", perimeter ~ area^"//sig_str(exponent, 3)
   end function patch_detail

   !> A state's tangential step in the summary: the force and shift along x, the stick
   !> area, or gross sliding.
   function tangential_text(s, pixel) result(text)
      type(state_values), intent(in) :: s
      real(dp), intent(in) :: pixel
      character(len=:), allocatable :: text
      if (.not. allocated(s%stick)) then
         text = "tangential: none (no contact carries it)"
      else if (s%sliding) then
         text = "tangential "//sig_str(s%tangential_force(1), 6)//" nN: gross sliding, every contact at mu p (shift "// &
            sig_str(s%tangential_shift(1), 6)//" nm at the onset)"
      else
         text = "tangential "//sig_str(s%tangential_force(1), 6)//" nN, shift "//sig_str(s%tangential_shift(1), 6)// &
            " nm; "//int_str(s%stick_contacts)//" of "//int_str(s%contacts)//" contacts stick ("// &
            sig_str(s%stick_contacts*pixel**2, 4)//" nm^2, "// &
            sig_str(100*real(s%stick_contacts, dp)/max(s%contacts, 1), 4)//" %); "//int_str(s%tangential_iterations)// &
            " iterations, residual "//sig_str(s%tangential_residual, 2)
      end if
   end function tangential_text

   !> " (+- B nm)" after an approach the solver bounds (B >= 0), "" otherwise.
   function bound_text(bound) result(text)
      real(dp), intent(in) :: bound
      character(len=:), allocatable :: text
      text = ""
      if (bound >= 0) text = " (+- "//sig_str(bound, 2)//" nm)"
   end function bound_text
end module femcod_run_summary
