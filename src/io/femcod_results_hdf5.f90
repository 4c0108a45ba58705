!> A run's PREFIX.h5 (/deck /surfaces /history /contacts /loads/<kkk> /mesh /run;
!> doc/results.md) and its XDMF description PREFIX.xdmf (the maps on a quadrilateral mesh
!> for ParaView and meshio); the fingerprint a finished set stores.
module femcod_results_hdf5
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_IO
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str, xml_escape
   use femcod_contact_result, only: contact_result, load_state, stop_reason_text, event_path_diagnostics, &
      legacy_diagnostics, event_checks, legacy_checks, cg_work
   use femcod_hdf5, only: h5_file, h5_create, h5_open, h5_reopen, h5_close, h5_group, h5_write, h5_attribute, &
      h5_read_string_attribute, h5_flat_view, h5_read
   use femcod_maps, only: state_maps, tangential_step_maps, state_pressure_map
   use femcod_patches, only: contact_patches, perimeter_area_fit
   use femcod_shear_model, only: friction_coefficient
   use femcod_state_record, only: state_attributes
   use femcod_result_schema, only: run_info, TANGENTIAL_MAPS, TANGENTIAL_UNITS, result_name, step_plastic, area_fit, &
      load_group, run_boundary, has_adhesion
   implicit none
   private
   public :: write_hdf5, xdmf_text, stored_fingerprint, start_result_file, stream_gap_map, read_streamed_gap_map

contains

   !> The HDF5 file (schema in doc/results.md).
   subroutine write_hdf5(tmp, deck, res, info, maps, status, started)
      character(len=*), intent(in) :: tmp
      !> Its height maps only where `tmp` was not started.
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      type(run_info), intent(in) :: info
      type(state_maps), intent(in) :: maps(:)
      type(status_type), intent(inout) :: status
      !> `tmp` was started before the solve (start_result_file: /surfaces is in it).
      logical, intent(in), optional :: started
      logical :: surfaces_in_file
      type(h5_file) :: file
      type(status_type) :: local
      character(len=:), allocatable :: g, scene
      real(dp) :: area_pixel, region, exponent, prefactor
      integer :: k, n
      if (status%code /= 0) return
      n = res%nsteps
      area_pixel = deck%pixel**2
      region = deck%np**2*area_pixel
      surfaces_in_file = .false.
      if (present(started)) surfaces_in_file = started
      ! The heights and the /loads group (start_result_file), and the gap maps streamed
      ! while the run solved (stream_gap_map), are in the file already.
      if (surfaces_in_file) then
         call h5_reopen(tmp, file, local)
      else
         call h5_create(tmp, file, local)
      end if
      file%path = result_name(tmp)
      call h5_group(file, "/deck", local)
      call h5_attribute(file, "/deck", "label", deck%label, local)
      call h5_attribute(file, "/deck", "NP", deck%np, local)
      call h5_attribute(file, "/deck", "pixel_nm", deck%pixel, local)
      call h5_attribute(file, "/deck", "MAXCONT", deck%maxcont, local)
      call h5_attribute(file, "/deck", "young_lower_GPa", deck%young(1), local)
      call h5_attribute(file, "/deck", "young_upper_GPa", deck%young(2), local)
      call h5_attribute(file, "/deck", "young_contact_GPa", deck%young(3), local)
      call h5_attribute(file, "/deck", "poisson_lower", deck%poisson(1), local)
      call h5_attribute(file, "/deck", "poisson_upper", deck%poisson(2), local)
      call h5_attribute(file, "/deck", "poisson_contact", deck%poisson(3), local)
      if (.not. surfaces_in_file) call write_surfaces(file, deck, local)
      call h5_group(file, "/history", local)
      call h5_write(file, "/history/step", [(k, k = 1, n)], "1", local)
      call h5_write(file, "/history/contacts", res%step_contacts(1:n), "1", local)
      call h5_write(file, "/history/load", res%step_load(1:n), "nN", local)
      call h5_write(file, "/history/approach", res%step_approach(1:n), "nm", local)
      call h5_write(file, "/history/area", res%step_contacts(1:n)*area_pixel, "nm^2", local)
      call h5_write(file, "/history/area_fraction", res%step_contacts(1:n)*area_pixel/region, "1", local)
      call h5_write(file, "/history/n_above_hardness", res%step_above_hardness(1:n), "1", local)
      call h5_write(file, "/history/n_plastic", [(step_plastic(res, k), k = 1, n)], "1", local)
      if (info%friction) then
         call h5_write(file, "/history/friction", res%step_friction(1:n), "nN", local)
         call h5_write(file, "/history/friction_coefficient", &
            [(friction_coefficient(res%step_friction(k), res%step_load(k), res%step_contacts(k)), k = 1, n)], "1", local)
      end if
      call h5_group(file, "/contacts", local)
      call h5_attribute(file, "/contacts", "load_nN", res%reported_load, local)
      call h5_write(file, "/contacts/i", res%contact_i, "1", local)
      call h5_write(file, "/contacts/j", res%contact_j, "1", local)
      call h5_write(file, "/contacts/step", res%contact_step, "1", local)
      call h5_write(file, "/contacts/force", res%contact_force, "nN", local)
      call h5_write(file, "/contacts/pressure", res%contact_force/area_pixel, "GPa", local)
      if (.not. surfaces_in_file) call h5_group(file, "/loads", local)
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         g = load_group(k, size(res%states))
         associate(s => res%states(k))
            if (.not. maps(k)%gap_in_file) call h5_group(file, g, local)
            call state_attributes(file, g, k, s%state_values, deck%pixel, deck%np, info, cg_work(res, k), local)
            if (info%tangential) call write_tangential(file, g, deck, s, local)
            call write_patches(file, g, maps(k)%patches, local)
            call write_pressure(file, g, deck, s, local)
            if (.not. maps(k)%gap_in_file) call h5_write(file, g//"/gap", maps(k)%gap, "nm", local, &
               compress=mostly_zero(maps(k)%gap))
            if (allocated(s%plastic)) call h5_write(file, g//"/plastic_displacement", s%plastic, "nm", local, &
               compress=mostly_zero(s%plastic))
         end associate
      end do
      call write_mesh(file, deck, res, info%tangential, local)
      call h5_group(file, "/run", local)
      call h5_attribute(file, "/run", "femcod_version", info%version, local)
      if (allocated(info%command_line)) call h5_attribute(file, "/run", "command_line", info%command_line, local)
      if (allocated(info%host)) call h5_attribute(file, "/run", "host", info%host, local)
      if (allocated(info%started)) call h5_attribute(file, "/run", "started", info%started, local)
      if (allocated(info%finished)) call h5_attribute(file, "/run", "finished", info%finished, local)
      call h5_attribute(file, "/run", "solver", info%solver, local)
      call h5_attribute(file, "/run", "boundary", run_boundary(info), local)
      call h5_attribute(file, "/run", "rms_slope", info%rms_slope, local)
      call h5_attribute(file, "/run", "composite_modulus_GPa", info%composite_modulus, local)
      if (has_adhesion(info)) then
         call h5_attribute(file, "/run", "adhesion", info%adhesion, local)
         call h5_attribute(file, "/run", "work_of_adhesion_J_m2", info%work, local)
         call h5_attribute(file, "/run", "adhesion_range_nm", info%range, local)
      end if
      if (info%tangential) then
         call h5_attribute(file, "/run", "coulomb_friction", info%coulomb, local)
         call h5_attribute(file, "/run", "dundurs_beta", info%beta, local)
      end if
      if (info%friction) then
         call h5_attribute(file, "/run", "shear_strength_GPa", info%shear_strength, local)
         call h5_attribute(file, "/run", "shear_slope", info%shear_slope, local)
         if (info%shear_cap < huge(1.0_dp)) call h5_attribute(file, "/run", "shear_cap_GPa", info%shear_cap, local)
      end if
      call h5_attribute(file, "/run", "options", info%options, local)
      call h5_attribute(file, "/run", "wall_time_s", res%wall_seconds, local)
      call h5_attribute(file, "/run", "stop_reason", stop_reason_text(res%stop_reason), local)
      scene = ""
      do k = 1, size(info%scene)
         scene = scene//info%scene(k)%s
         if (k < size(info%scene)) scene = scene//"; "
      end do
      call h5_attribute(file, "/run", "scene_left_out", scene, local)
      if (allocated(info%inputs)) call h5_attribute(file, "/run", "inputs", joined(info%inputs), local)
      if (allocated(info%digests)) call h5_attribute(file, "/run", "input_sha256", joined(info%digests), local)
      if (allocated(info%fingerprint)) call h5_attribute(file, "/run", "fingerprint", info%fingerprint, local)
      call write_run_checks(file, res, local)
      call area_fit(deck, res, exponent, prefactor)
      call h5_write(file, "/run/area_load_exponent", exponent, "1", local)
      call h5_write(file, "/run/area_load_prefactor", prefactor, "nm^2/nN^exponent", local)
      call h5_close(file, local)
      if (local%code /= 0) call set_error(status, STATUS_IO, local%message)
   end subroutine write_hdf5

   !> /mesh: the pixels as quadrilaterals for XDMF readers that want an explicit mesh
   !> (meshio reads no structured grid). Node (a, b), a = 0..NP across the rows and
   !> b = 0..NP across the columns, is number a*(NP+1) + b at x = b d, y = (NP - a) d:
   !> row 1 on top, as in the figures, in the XY plane. Cell (i, j) is number
   !> (i-1)*NP + (j-1), the C order of the NP x NP maps, which /mesh/cells/* show as
   !> lists (virtual datasets, no copy). Both arrays are deflated (regular: small).
   subroutine write_mesh(file, deck, res, tangential, status)
      type(h5_file), intent(in) :: file
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      !> With the maps of a tangential step (shear_x, shear_y, stick, slip).
      logical, intent(in) :: tangential
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: nodes(:, :)
      integer, allocatable :: quads(:, :)
      integer :: n, a, b, i, j, c, k, m
      if (status%code /= 0) return
      n = deck%np
      allocate(nodes((n + 1)**2, 2), quads(n*n, 4))
      !$omp parallel do private(b)
      do a = 0, n
         do b = 0, n
            nodes(a*(n + 1) + b + 1, 1) = b*deck%pixel
            nodes(a*(n + 1) + b + 1, 2) = (n - a)*deck%pixel
         end do
      end do
      !$omp parallel do private(j, c)
      do i = 1, n
         do j = 1, n
            c = (i - 1)*n + j
            ! Counter-clockwise seen from +z: top-left, bottom-left, bottom-right, top-right.
            quads(c, 1) = (i - 1)*(n + 1) + (j - 1)
            quads(c, 2) = i*(n + 1) + (j - 1)
            quads(c, 3) = i*(n + 1) + j
            quads(c, 4) = (i - 1)*(n + 1) + j
         end do
      end do
      call h5_group(file, "/mesh", status)
      call h5_write(file, "/mesh/nodes_xy", nodes, "nm", status, compress=.true.)
      call h5_write(file, "/mesh/quadrilaterals", quads, "node number from 0", status, compress=.true.)
      call h5_group(file, "/mesh/cells", status)
      call h5_flat_view(file, "/mesh/cells/lower_nm", "/surfaces/lower", "nm", status)
      call h5_flat_view(file, "/mesh/cells/upper_nm", "/surfaces/upper", "nm", status)
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         call h5_flat_view(file, "/mesh/cells/"//xdmf_name("pressure_GPa", k, size(res%states)), &
            load_group(k, size(res%states))//"/pressure", "GPa", status)
         call h5_flat_view(file, "/mesh/cells/"//xdmf_name("gap_nm", k, size(res%states)), &
            load_group(k, size(res%states))//"/gap", "nm", status)
         if (.not. tangential) cycle
         do m = 1, size(TANGENTIAL_MAPS)
            call h5_flat_view(file, "/mesh/cells/"//xdmf_name(trim(TANGENTIAL_MAPS(m)), k, size(res%states)), &
               load_group(k, size(res%states))//"/"//trim(TANGENTIAL_MAPS(m)), trim(TANGENTIAL_UNITS(m)), status)
         end do
      end do
   end subroutine write_mesh

   !> Start PREFIX.h5's temporary `tmp` before the solve with the problem's two height
   !> maps (/surfaces) and the /loads group: the solve may then free the heights
   !> (contact_options%release_heights), and write_hdf5 (`started`) completes the file.
   subroutine start_result_file(tmp, deck, status)
      character(len=*), intent(in) :: tmp
      type(contact_problem), intent(in) :: deck
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      call h5_create(tmp, file, status)
      file%path = result_name(tmp)
      call write_surfaces(file, deck, status)
      call h5_group(file, "/loads", status)
      call h5_close(file, status)
   end subroutine start_result_file

   !> /surfaces: the lower and upper heights (nm), deflated where mostly zero (a flat).
   subroutine write_surfaces(file, deck, status)
      type(h5_file), intent(in) :: file
      type(contact_problem), intent(in) :: deck
      type(status_type), intent(inout) :: status
      call h5_group(file, "/surfaces", status)
      call h5_write(file, "/surfaces/lower", deck%lower, "nm", status, compress=mostly_zero(deck%lower))
      call h5_write(file, "/surfaces/upper", deck%upper, "nm", status, compress=mostly_zero(deck%upper))
   end subroutine write_surfaces

   !> State k of n's gap map (nm), written as soon as the state is solved into the
   !> temporary `tmp` of PREFIX.h5 (start_result_file began it; write_hdf5 completes it):
   !> a run holds one state's gap map, not all of them.
   subroutine stream_gap_map(tmp, k, n, gap, status)
      character(len=*), intent(in) :: tmp
      integer, intent(in) :: k, n
      real(dp), intent(in) :: gap(:, :)
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      character(len=:), allocatable :: g
      call h5_reopen(tmp, file, status)
      file%path = result_name(tmp)
      g = load_group(k, n)
      call h5_group(file, g, status)
      call h5_write(file, g//"/gap", gap, "nm", status, compress=mostly_zero(gap))
      call h5_close(file, status)
   end subroutine stream_gap_map

   !> State k of n's gap map back from `tmp` (stream_gap_map), for its figure.
   subroutine read_streamed_gap_map(tmp, k, n, gap, status)
      character(len=*), intent(in) :: tmp
      integer, intent(in) :: k, n
      real(dp), allocatable, intent(out) :: gap(:, :)
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      call h5_reopen(tmp, file, status)
      call h5_read(file, load_group(k, n)//"/gap", gap, status, STATUS_IO)
      call h5_close(file, status)
   end subroutine read_streamed_gap_map

   !> A state's pressure map (GPa) in its load group, formed from its contact list here
   !> and freed after: a run's maps are not all held at once.
   subroutine write_pressure(file, g, deck, s, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: g
      type(contact_problem), intent(in) :: deck
      type(load_state), intent(in) :: s
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: pressure(:, :)
      pressure = state_pressure_map(deck%np, deck%pixel, s)
      call h5_write(file, g//"/pressure", pressure, "GPa", status, compress=mostly_zero(pressure))
   end subroutine write_pressure

   !> A state's tangential step in its load group (its attributes: state_attributes): the
   !> traction maps tau_x, tau_y (GPa) and the stick and slip maps (1 where the contact
   !> sticks, or slips; 0 elsewhere).
   subroutine write_tangential(file, g, deck, s, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: g
      type(contact_problem), intent(in) :: deck
      type(load_state), intent(in) :: s
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: map(:, :, :)
      map = tangential_step_maps(deck%np, deck%pixel, s)
      call h5_write(file, g//"/shear_x", map(:, :, 1), "GPa", status, compress=mostly_zero(map(:, :, 1)))
      call h5_write(file, g//"/shear_y", map(:, :, 2), "GPa", status, compress=mostly_zero(map(:, :, 2)))
      call h5_write(file, g//"/stick", map(:, :, 3), "1", status, compress=mostly_zero(map(:, :, 3)))
      call h5_write(file, g//"/slip", map(:, :, 4), "1", status, compress=mostly_zero(map(:, :, 4)))
   end subroutine write_tangential

   !> Whether at least half of a map is zero: such maps (the pressure below half contact, a
   !> flat surface, no plastic displacement) are stored deflated (h5_write's compress), a
   !> small fraction of their size, and sooner than written whole.
   pure logical function mostly_zero(map)
      real(dp), intent(in) :: map(:, :)
      mostly_zero = 2*count(map == 0) >= size(map)
   end function mostly_zero

   !> /run's datasets of the solver's checks: the event path's (zeros for cg) and the
   !> legacy solver's conditioning (its defaults, pivot loss 1 and condition 0, for the
   !> others), the same datasets for every solver.
   !> A load group's contact patches (their counts: state_attributes): the perimeter-area
   !> fit as an attribute,
   !> each patch's area and perimeter as datasets (when there are patches).
   subroutine write_patches(file, g, patches, local)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: g
      type(contact_patches), intent(in) :: patches
      type(status_type), intent(inout) :: local
      real(dp) :: exponent, prefactor
      call perimeter_area_fit(patches%area4, patches%perimeter4, exponent, prefactor)
      call h5_attribute(file, g, "patch_perimeter_exponent", exponent, local)
      if (patches%count4 > 0) then
         call h5_write(file, g//"/patch_area_4", patches%area4, "pixels", local)
         call h5_write(file, g//"/patch_perimeter_4", patches%perimeter4, "pixel sides", local)
      end if
      if (patches%count8 > 0) then
         call h5_write(file, g//"/patch_area_8", patches%area8, "pixels", local)
         call h5_write(file, g//"/patch_perimeter_8", patches%perimeter8, "pixel sides", local)
      end if
   end subroutine write_patches

   subroutine write_run_checks(file, res, local)
      type(h5_file), intent(inout) :: file
      type(contact_result), intent(in) :: res
      type(status_type), intent(inout) :: local
      type(event_path_diagnostics) :: checks
      type(legacy_diagnostics) :: legacy
      checks = event_checks(res)
      legacy = legacy_checks(res)
      call h5_write(file, "/run/missed_during_run", checks%missed_during_run, "1", local)
      call h5_write(file, "/run/missed_final_check", checks%missed_final_check, "1", local)
      call h5_write(file, "/run/max_penetration", checks%max_penetration, "nm", local)
      call h5_write(file, "/run/final_resolve_difference", checks%final_check_difference, "1", local)
      call h5_write(file, "/run/releases", checks%releases, "1", local)
      call h5_write(file, "/run/fft_search_steps", checks%fft_steps, "1", local)
      call h5_write(file, "/run/trfact_pivot_loss", legacy%pivot_loss, "1", local)
      call h5_write(file, "/run/trfact_condition", legacy%condition, "1", local)
      call h5_write(file, "/run/exact_evaluations", real(checks%evaluations, dp), "1", local)
   end subroutine write_run_checks

   !> The name of load k's map among the cell arrays: pressure_GPa_load001.
   function xdmf_name(what, k, n) result(name)
      character(len=*), intent(in) :: what
      integer, intent(in) :: k, n
      character(len=:), allocatable :: name, group
      group = load_group(k, n)
      name = what//"_load"//group(len("/loads/") + 1:)
   end function xdmf_name

   !> XDMF 3: one uniform grid (the form meshio reads; ParaView too) of NP^2
   !> quadrilaterals in the XY plane (/mesh), with the surfaces and, for every reached
   !> load, its pressure and gap as cell arrays (the load in nN is in the array's name
   !> and in the HDF5 group).
   function xdmf_text(h5name, deck, res, tangential) result(x)
      character(len=*), intent(in) :: h5name
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      !> With the maps of a tangential step.
      logical, intent(in) :: tangential
      character(len=:), allocatable :: x
      character(len=1), parameter :: nl = new_line("a")
      character(len=:), allocatable :: file
      integer :: k, n
      n = deck%np
      file = xml_escape(h5name)
      x = '<?xml version="1.0" ?>'//nl//'<Xdmf Version="3.0">'//nl//' <Domain>'//nl// &
         '  <Grid Name="'//xml_escape(shortened(deck%label))//'" GridType="Uniform">'//nl// &
         '   <Topology TopologyType="Quadrilateral" NumberOfElements="'//int_str(n*n)//'">'//nl// &
         '    <DataItem Format="HDF" NumberType="Int" Precision="4" Dimensions="'//int_str(n*n)//' 4">'// &
         file//':/mesh/quadrilaterals</DataItem>'//nl//'   </Topology>'//nl// &
         '   <Geometry GeometryType="XY">'//nl// &
         '    <DataItem Format="HDF" NumberType="Float" Precision="8" Dimensions="'//int_str((n + 1)**2)//' 2">'// &
         file//':/mesh/nodes_xy</DataItem>'//nl//'   </Geometry>'//nl// &
         attribute("lower_nm")//attribute("upper_nm")
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         x = x//attribute(xdmf_name("pressure_GPa", k, size(res%states)))// &
            attribute(xdmf_name("gap_nm", k, size(res%states)))
         if (tangential) x = x//attribute(xdmf_name("shear_x", k, size(res%states)))// &
            attribute(xdmf_name("shear_y", k, size(res%states)))//attribute(xdmf_name("stick", k, size(res%states)))// &
            attribute(xdmf_name("slip", k, size(res%states)))
      end do
      x = x//'  </Grid>'//nl//' </Domain>'//nl//'</Xdmf>'//nl
   contains
      function attribute(name) result(a)
         character(len=*), intent(in) :: name
         character(len=:), allocatable :: a
         a = '   <Attribute Name="'//name//'" AttributeType="Scalar" Center="Cell">'//nl// &
            '    <DataItem Format="HDF" NumberType="Float" Precision="8" Dimensions="'//int_str(n*n)//'">'// &
            file//':/mesh/cells/'//name//'</DataItem>'//nl//'   </Attribute>'//nl
      end function attribute
      function shortened(label) result(t)
         character(len=*), intent(in) :: label
         character(len=:), allocatable :: t
         t = label(1:min(len(label), 60))
      end function shortened
   end function xdmf_text

   !> The fingerprint a result file records in /run ("" when it has none or cannot be
   !> read).
   function stored_fingerprint(path) result(hex)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: hex
      type(h5_file) :: file
      type(status_type) :: local
      hex = ""
      call h5_open(path, file, local, STATUS_IO)
      call h5_read_string_attribute(file, "/run", "fingerprint", 80, hex, local, STATUS_IO)
      call h5_close(file, local)
      if (local%code /= 0) hex = ""
   end function stored_fingerprint

   !> Lines joined by "; ".
   function joined(lines) result(text)
      type(string_type), intent(in) :: lines(:)
      character(len=:), allocatable :: text
      integer :: k
      text = ""
      do k = 1, size(lines)
         text = text//lines(k)%s
         if (k < size(lines)) text = text//"; "
      end do
   end function joined
end module femcod_results_hdf5
