!> A run's PREFIX.summary.json: what the printed summary says, as numbers with units.
module femcod_results_json
   use femcod_kinds, only: dp
   use femcod_memory, only: peak_resident_bytes
   use femcod_problem, only: contact_problem
   use femcod_strings, only: int_str, json_string, json_number, string_type
   use femcod_contact_result, only: contact_result, stop_reason_text, event_path_diagnostics, &
      legacy_diagnostics, cg_diagnostics, cg_state_diagnostics, event_checks, cg_work
   use femcod_maps, only: state_maps
   use femcod_patches, only: contact_patches, perimeter_area_fit
   use femcod_state_record, only: state_json
   use femcod_result_schema, only: run_info, area_fit, run_boundary, has_adhesion
   implicit none
   private
   public :: summary_json, run_header_json

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
      character(len=:), allocatable :: loads, detail
      real(dp) :: exponent, prefactor
      type(event_path_diagnostics) :: checks
      integer :: k, last
      checks = event_checks(res)
      last = res%nsteps
      loads = ""
      do k = 1, size(res%states)
         detail = ""
         if (res%states(k)%reached) detail = patch_detail(maps(k)%patches)
         loads = loads//'    '//state_json(res%states(k)%state_values, k, size(res%states), deck%pixel, deck%np, info, &
            cg_work(res, k), detail, "")//trim(merge(",", " ", k < size(res%states)))//nl
      end do
      call area_fit(deck, res, exponent, prefactor)
      j = run_header_json(prefix, deck, info)// &
         '  "steps": '//int_str(last)//','//nl// &
         '  "stopped": '//json_string(stop_reason_text(res%stop_reason))//','//nl
      if (last > 0) then
         j = j//'  "last_step": {"contacts": '//int_str(res%step_contacts(last))//', "load_nN": '// &
            json_number(res%step_load(last))//', "approach_nm": '//json_number(res%step_approach(last))// &
            ', "area_nm2": '//json_number(res%step_contacts(last)*deck%pixel**2)//', "area_fraction": '// &
            json_number(res%step_contacts(last)*deck%pixel**2/(deck%np**2*deck%pixel**2))//'},'//nl
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

      !> A state's patches beyond their counts: the largest, the perimeter-area exponent.
      function patch_detail(patches) result(t)
         type(contact_patches), intent(in) :: patches
         character(len=:), allocatable :: t
         real(dp) :: e, p
         call perimeter_area_fit(patches%area4, patches%perimeter4, e, p)
         t = ', "largest_patch_pixels": '//int_str(maxval([0, patches%area8]))// &
            ', "patch_perimeter_exponent": '//json_number(e)
      end function patch_detail
   end function summary_json

   !> The summary file's opening: '{', then the program, the command, the machine and the
   !> times, the results' prefix, the scene (from `deck`: label, grid, materials), the
   !> solver, the boundary and the adhesion law, a line each.
   function run_header_json(prefix, deck, info) result(j)
      character(len=*), intent(in) :: prefix
      type(contact_problem), intent(in) :: deck
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: j
      character(len=1), parameter :: nl = new_line("a")
      j = '{'//nl// &
         '  "femcod_version": '//json_string(info%version)//','//nl// &
         '  "command_line": '//json_string(text_or_empty(info%command_line))//','//nl// &
         '  "host": '//json_string(text_or_empty(info%host))//','//nl// &
         '  "openmp": {"threads": '//int_str(info%threads)//', "wait_policy": '// &
         json_string(text_or_empty(info%wait_policy))//'},'//nl// &
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
         '  "kappa_scale": {"rms_slope": '//json_number(info%rms_slope)//', "composite_modulus_GPa": '// &
         json_number(info%composite_modulus)//'},'//nl// &
         '  "model": '//string_list_json(info%scene)//','//nl// &
         '  "warnings": '//string_list_json(info%warnings)//','//nl// &
         adhesion_json(info)
   end function run_header_json

   !> A JSON array of the strings (unallocated: []).
   function string_list_json(list) result(j)
      type(string_type), allocatable, intent(in) :: list(:)
      character(len=:), allocatable :: j
      integer :: k
      j = "["
      if (allocated(list)) then
         do k = 1, size(list)
            j = j//json_string(list(k)%s)
            if (k < size(list)) j = j//", "
         end do
      end if
      j = j//"]"
   end function string_list_json

   !> The summary file's adhesion fields (a line each, with the comma), or nothing.
   function adhesion_json(info) result(text)
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      text = ""
      if (has_adhesion(info)) text = '  "adhesion": {"law": '//json_string(info%adhesion)// &
         ', "work_of_adhesion_J_m2": '//json_number(info%work)//', "range_nm": '//json_number(info%range)//'},'// &
         new_line("a")
   end function adhesion_json

   !> The text, or "" when it is not there.
   function text_or_empty(t) result(r)
      character(len=:), allocatable, intent(in) :: t
      character(len=:), allocatable :: r
      r = ""
      if (allocated(t)) r = t
   end function text_or_empty
end module femcod_results_json
