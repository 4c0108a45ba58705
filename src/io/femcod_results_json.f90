!> A run's PREFIX.summary.json: what the printed summary says, as numbers with units.
module femcod_results_json
   use femcod_kinds, only: dp
   use femcod_memory, only: peak_resident_bytes
   use femcod_problem, only: contact_problem
   use femcod_strings, only: int_str, json_string, json_number
   use femcod_contact_result, only: contact_result, load_state, stop_reason_text, event_path_diagnostics, &
      legacy_diagnostics, cg_diagnostics, cg_state_diagnostics, event_checks, cg_work
   use femcod_maps, only: state_maps
   use femcod_patches, only: contact_patches, perimeter_area_fit
   use femcod_shear_model, only: friction_coefficient
   use femcod_result_schema, only: run_info, area_fit, load_group, run_boundary, has_adhesion
   implicit none
   private
   public :: summary_json

contains

   !> PREFIX.summary.json: what the summary prints, as numbers whose names carry their
   !> units, for scripts; the solver's own counters last.
   function summary_json(prefix, deck, res, maps, info, write_seconds) result(j)
      character(len=*), intent(in) :: prefix
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      type(state_maps), intent(in) :: maps(:)
      type(run_info), intent(in) :: info
      !> Seconds of writing PREFIX.h5 and of the text files and figures before this one.
      real(dp), intent(in) :: write_seconds(2)
      character(len=:), allocatable :: j
      character(len=1), parameter :: nl = new_line("a")
      character(len=:), allocatable :: loads
      real(dp) :: area_pixel, exponent, prefactor
      type(event_path_diagnostics) :: checks
      type(cg_state_diagnostics) :: work
      integer :: k, last
      checks = event_checks(res)
      area_pixel = deck%pixel**2
      last = res%nsteps
      loads = ""
      do k = 1, size(res%states)
         associate(s => res%states(k))
            loads = loads//'    {"load_nN": '//json_number(s%load)//', "reached": '// &
               trim(merge("true ", "false", s%reached))
            if (s%reached) loads = loads//', "approach_nm": '//json_number(s%approach)//', "contacts": '// &
               int_str(s%contacts)//', "area_nm2": '//json_number(s%contacts*area_pixel)//', "area_fraction": '// &
               json_number(s%contacts/real(deck%np, dp)**2)//', "max_pressure_GPa": '//json_number(s%max_pressure)// &
               ', "n_above_hardness": '//int_str(s%n_above_hardness)//', "n_plastic": '// &
               int_str(s%n_plastic)//', "plastic_volume_nm3": '//json_number(s%plastic_volume)//', "hdf5_group": '// &
               json_string(load_group(k, size(res%states)))
            if (s%reached) loads = loads//patch_fields(maps(k)%patches)
            work = cg_work(res, k)
            if (s%reached .and. work%approach_bound >= 0) loads = loads//', "approach_error_bound_nm": '// &
               json_number(work%approach_bound)
            if (s%reached .and. info%tangential) loads = loads//', "tangential_force_nN": '// &
               json_number(s%tangential_force(1))//', "tangential_shift_nm": '//json_number(s%tangential_shift(1))// &
               ', "stick_contacts": '//int_str(stick_count(s))//', "stick_area_nm2": '// &
               json_number(stick_count(s)*area_pixel)//', "gross_sliding": '//trim(merge("true ", "false", s%sliding))
            if (s%reached .and. info%friction) loads = loads//', "friction_nN": '//json_number(s%friction)// &
               ', "friction_coefficient": '//json_number(friction_coefficient(s%friction, s%load, s%contacts))
            if (s%reached .and. (has_adhesion(info) .or. info%solver == "cg")) loads = loads//', "mean_gap_nm": '// &
               json_number(s%mean_gap)
            if (s%reached .and. has_adhesion(info)) loads = loads//', "attractive_pixels": '// &
               int_str(s%attractive)//', "attractive_load_nN": '//json_number(s%attractive_load)// &
               ', "jump": '//int_str(s%jump)
            loads = loads//'}'//trim(merge(",", " ", k < size(res%states)))//nl
         end associate
      end do
      call area_fit(deck, res, exponent, prefactor)
      j = '{'//nl// &
         '  "femcod_version": '//json_string(info%version)//','//nl// &
         '  "command_line": '//json_string(text_or_empty(info%command_line))//','//nl// &
         '  "host": '//json_string(text_or_empty(info%host))//','//nl// &
         '  "started": '//json_string(text_or_empty(info%started))//','//nl// &
         '  "finished": '//json_string(text_or_empty(info%finished))//','//nl// &
         '  "results": '//json_string(prefix)//','//nl// &
         '  "scene": {"label": '//json_string(deck%label)//', "NP": '//int_str(deck%np)//', "pixel_nm": '// &
         json_number(deck%pixel)//', "MAXCONT": '//int_str(deck%maxcont)//','//nl// &
         '    "young_GPa": {"lower": '//json_number(deck%young(1))//', "upper": '//json_number(deck%young(2))// &
         ', "contact": '//json_number(deck%young(3))//'},'//nl// &
         '    "poisson": {"lower": '//json_number(deck%poisson(1))//', "upper": '//json_number(deck%poisson(2))// &
         ', "contact": '//json_number(deck%poisson(3))//'}},'//nl// &
         '  "solver": '//json_string(info%solver)//','//nl// &
         '  "boundary": '//json_string(run_boundary(info))//','//nl// &
         adhesion_json(info)// &
         '  "steps": '//int_str(last)//','//nl// &
         '  "stopped": '//json_string(stop_reason_text(res%stop_reason))//','//nl
      if (last > 0) then
         j = j//'  "last_step": {"contacts": '//int_str(res%step_contacts(last))//', "load_nN": '// &
            json_number(res%step_load(last))//', "approach_nm": '//json_number(res%step_approach(last))//'},'//nl
      end if
      j = j//'  "loads": ['//nl//loads//'  ],'//nl// &
         '  "area_load_fit": {"exponent": '//json_number(exponent)//', "prefactor_nm2": '// &
         json_number(prefactor)//'},'//nl// &
         '  "wall_time_s": '//json_number(res%wall_seconds)//','//nl// &
         '  "timings_s": {"read_inputs": '//json_number(info%read_seconds)//', "input_digests": '// &
         json_number(info%digest_seconds)//', "solve": '//json_number(res%wall_seconds)//', "maps": '// &
         json_number(info%maps_seconds)//', "write_hdf5": '//json_number(write_seconds(1))// &
         ', "write_text_and_figures": '//json_number(write_seconds(2))//'},'//nl// &
         '  "memory_bytes": {"estimated_peak": '//int_str(res%estimated_peak_bytes)//', "peak": '// &
         int_str(peak_resident_bytes())//'},'//nl// &
         '  "checks": {"penetrating_pixels_at_end": '//int_str(checks%missed_final_check)// &
         ', "deepest_penetration_nm": '//json_number(checks%max_penetration)//', "found_late": '// &
         int_str(checks%missed_during_run)//', "releases": '//int_str(checks%releases)// &
         ', "exact_resolve_difference": '//json_number(checks%final_check_difference)//'},'//nl// &
         '  "solver_details": '//solver_details()//nl//'}'//nl
   contains
      !> What each solver counts of its own work: the type of diagnostics it returned.
      function solver_details() result(d)
         character(len=:), allocatable :: d
         integer :: m
         d = '{}'
         if (.not. allocated(res%diagnostics)) return
         select type (diag => res%diagnostics)
         type is (event_path_diagnostics)
            d = '{"exact_pixel_evaluations": '//int_str(diag%evaluations)//', "fft_search_steps": '// &
               int_str(diag%fft_steps)//', "cache_hits": '//int_str(diag%cache_hits)//', "cache_misses": '// &
               int_str(diag%cache_misses)//', "cache_refills": '//int_str(diag%cache_refills)//'}'
         type is (legacy_diagnostics)
            d = '{"trfact_condition": '//json_number(diag%condition)//', "trfact_pivot_loss": '// &
               json_number(diag%pivot_loss)//'}'
         type is (cg_diagnostics)
            d = '{"cg": ['
            do m = 1, size(res%states)
               d = d//'{"load_nN": '//json_number(res%states(m)%load)//', "iterations": '// &
                  int_str(diag%states(m)%iterations)//', "residual": '//json_number(diag%states(m)%residual)// &
                  ', "penetration_nm": '//json_number(diag%states(m)%penetration)//', "contact_gap_nm": '// &
                  json_number(diag%states(m)%contact_gap)//', "load_error": '// &
                  json_number(diag%states(m)%load_error)//'}'//trim(merge(", ", "  ", m < size(res%states)))
            end do
            d = d//']}'
         end select
      end function solver_details

      !> The patches of a state: counts, the largest, the perimeter-area exponent.
      function patch_fields(patches) result(t)
         type(contact_patches), intent(in) :: patches
         character(len=:), allocatable :: t
         real(dp) :: e, p
         call perimeter_area_fit(patches%area4, patches%perimeter4, e, p)
         t = ', "patches_4": '//int_str(patches%count4)//', "patches_8": '//int_str(patches%count8)// &
            ', "largest_patch_pixels": '//int_str(maxval([0, patches%area8]))// &
            ', "patch_perimeter_exponent": '//json_number(e)
      end function patch_fields
      function text_or_empty(t) result(r)
         character(len=:), allocatable, intent(in) :: t
         character(len=:), allocatable :: r
         r = ""
         if (allocated(t)) r = t
      end function text_or_empty
   end function summary_json

   !> The summary file's adhesion fields (a line each, with the comma), or nothing.
   function adhesion_json(info) result(text)
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      text = ""
      if (has_adhesion(info)) text = '  "adhesion": {"law": '//json_string(info%adhesion)// &
         ', "work_of_adhesion_J_m2": '//json_number(info%work)//', "range_nm": '//json_number(info%range)//'},'// &
         new_line("a")
   end function adhesion_json

   !> The contacts that stick after a state's tangential step (0 without one).
   pure integer function stick_count(s)
      type(load_state), intent(in) :: s
      stick_count = 0
      if (allocated(s%stick)) stick_count = count(s%stick)
   end function stick_count
end module femcod_results_json
