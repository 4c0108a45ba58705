!> Result files of a run, written under temporary names and renamed only when all of
!> them are complete, so a failed run leaves no partial result (doc/results.md):
!>   PREFIX.history.csv   step,contacts,load_nN,approach_nm,area_nm2,area_fraction,n_above_hardness
!>   PREFIX.loads.csv     load_nN,approach_nm,contacts,area_nm2,area_fraction,max_pressure_GPa,n_above_hardness
!>   PREFIX.contacts.csv  i,j,step,force_nN,pressure_GPa
!>   PREFIX.h5            /deck /surfaces /history /contacts /loads/<kkk> /mesh /run
!>   PREFIX.xdmf          the maps of PREFIX.h5 on a quadrilateral mesh (ParaView, meshio)
!>   PREFIX.summary.json  what the summary prints, as numbers with units
!>   PREFIX.load_approach.svg, PREFIX.area_load.svg, PREFIX.pressure_<k>.svg
module femcod_results
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use femcod_kinds, only: dp, i8
   use femcod_clock, only: wall_clock
   use femcod_memory, only: peak_resident_bytes
   use femcod_status, only: status_type, set_error, STATUS_IO
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str, text_builder, add_line, built_text, format_real, xml_escape, sig_str, &
      json_string, json_number, format_reals, integer_text
   use femcod_files, only: atomic_rename, remove_file, temporary_name, path_exists, write_bytes
   use femcod_contact_result, only: contact_result, load_state, stop_reason_text, event_path_diagnostics, &
      legacy_diagnostics, cg_diagnostics, cg_state_diagnostics, event_checks, legacy_checks, cg_work
   use femcod_hdf5, only: h5_file, h5_create, h5_open, h5_close, h5_group, h5_write, h5_attribute, &
      h5_read_string_attribute, h5_flat_view
   use femcod_maps, only: state_maps, tangential_step_maps
   use femcod_patches, only: contact_patches, perimeter_area_fit
   use femcod_svg, only: svg_plot, svg_pressure_map
   use femcod_richardson, only: power_law_fit
   use femcod_shear_model, only: friction_coefficient
   implicit none
   private
   public :: write_results, run_info, result_files, write_file_set, stored_fingerprint, load_group
   public :: pressure_figure_wanted, FIGURES_AUTO_LIMIT
   public :: HISTORY_HEADER, LOADS_HEADER, CONTACTS_HEADER, FRICTION_COLUMNS, TANGENTIAL_COLUMNS, PATCH_COLUMNS

   !> The CSV files' header lines (the help prints them from here).
   character(len=*), parameter :: HISTORY_HEADER = &
      "step,contacts,load_nN,approach_nm,area_nm2,area_fraction,n_above_hardness,n_plastic"
   character(len=*), parameter :: LOADS_HEADER = "load_nN,approach_nm,contacts,area_nm2,area_fraction,"// &
      "max_pressure_GPa,n_above_hardness,n_plastic,plastic_volume_nm3"
   character(len=*), parameter :: CONTACTS_HEADER = "i,j,step,force_nN,pressure_GPa"
   !> The columns every loads file ends with: the contact patches, 4- and 8-connected
   !> (model/femcod_patches).
   character(len=*), parameter :: PATCH_COLUMNS = ",patches_4,patches_8"
   !> The columns the shear model adds to the history and loads files.
   character(len=*), parameter :: FRICTION_COLUMNS = ",friction_nN,friction_coefficient"
   !> The maps of a tangential step in each load group (and on the mesh).
   character(len=*), parameter :: TANGENTIAL_MAPS(4) = [character(len=7) :: "shear_x", "shear_y", "stick", "slip"]
   character(len=*), parameter :: TANGENTIAL_UNITS(4) = [character(len=3) :: "GPa", "GPa", "1", "1"]
   !> The columns a tangential step adds to the loads file.
   character(len=*), parameter :: TANGENTIAL_COLUMNS = ",tangential_force_nN,tangential_shift_nm,stick_contacts,"// &
      "stick_fraction"

   !> What the run was, for /run in the HDF5 file.
   !> With --figures auto (the default) a pressure figure of every state up to this many
   !> requested states, beyond it of the last reached one only (1001 loads wrote 17 MB of
   !> figures).
   integer, parameter :: FIGURES_AUTO_LIMIT = 20

   type :: run_info
      character(len=:), allocatable :: version, solver, options
      !> Which states get a pressure figure (--figures): "all", "last", "none", or "auto"
      !> (unallocated too: all up to FIGURES_AUTO_LIMIT states, else the last).
      character(len=:), allocatable :: figures
      !> The lateral boundary, "free" or "periodic" (--boundary).
      character(len=:), allocatable :: boundary
      !> The adhesion law (--adhesion: "dugdale" or "exponential"; unallocated or "none":
      !> no adhesion), its work (J/m^2) and range (nm).
      character(len=:), allocatable :: adhesion
      real(dp) :: work = 0, range = 0
      !> With the shear model (--shear-strength, --shear-slope): true, and its tau0 (GPa),
      !> alpha (1) and cap (GPa; huge: none). Adds the friction columns and attributes.
      logical :: friction = .false.
      real(dp) :: shear_strength = 0, shear_slope = 0, shear_cap = huge(1.0_dp)
      !> With a tangential step (--tangential, --slip): true, its Coulomb coefficient, and
      !> Dundurs' beta of the materials (the coupling left out). Adds the tangential
      !> columns, attributes and maps.
      logical :: tangential = .false.
      real(dp) :: coulomb = 0, beta = 0
      !> What the scene left out, one line each.
      type(string_type), allocatable :: scene(:)
      !> The input files, one line each: the deck, or what each height file gave
      !> (format, channel, instrument, grid, scan and pixel size); each file's SHA-256;
      !> the fingerprint of the problem and options (a restart's check).
      type(string_type), allocatable :: inputs(:), digests(:)
      character(len=:), allocatable :: fingerprint
      !> The command as typed (femcod run ...), the machine, and when the run started
      !> and its results were written (ISO 8601 with the UTC offset).
      character(len=:), allocatable :: command_line, host, started, finished
      !> Wall seconds of the parts of the run before the writing: reading the inputs,
      !> their digests, the maps of the reached loads (the solve is the result's own).
      real(dp) :: read_seconds = 0, digest_seconds = 0, maps_seconds = 0
   end type run_info

contains

   !> The names of every file a run writes for `prefix` (with `nloads` requested loads).
   function result_files(prefix, nloads) result(names)
      character(len=*), intent(in) :: prefix
      integer, intent(in) :: nloads
      type(string_type), allocatable :: names(:)
      integer :: k
      allocate(names(0))
      names = [string_type(prefix//".history.csv"), string_type(prefix//".contacts.csv"), &
         string_type(prefix//".h5"), string_type(prefix//".xdmf"), string_type(prefix//".load_approach.svg"), &
         string_type(prefix//".area_load.svg"), string_type(prefix//".summary.json")]
      if (nloads > 0) names = [names, string_type(prefix//".loads.csv")]
      do k = 1, nloads
         names = [names, string_type(prefix//".pressure_"//int_str(k)//".svg")]
      end do
   end function result_files

   !> Whether state k gets its pressure figure PREFIX.pressure_<k>.svg under --figures
   !> `figures` (all, last, none, auto): only a reached state has one; "last" is the last
   !> reached state in the order asked; "auto" is all up to FIGURES_AUTO_LIMIT requested
   !> states, else last.
   pure logical function pressure_figure_wanted(res, k, figures) result(wanted)
      type(contact_result), intent(in) :: res
      integer, intent(in) :: k
      character(len=*), intent(in) :: figures
      character(len=:), allocatable :: rule
      wanted = .false.
      if (.not. res%states(k)%reached) return
      rule = figures
      if (rule == "auto") rule = trim(merge("all ", "last", size(res%states) <= FIGURES_AUTO_LIMIT))
      select case (rule)
      case ("all")
         wanted = .true.
      case ("last")
         wanted = .not. any(res%states(k + 1:)%reached)
      end select
   end function pressure_figure_wanted

   !> Write every result file for `prefix`; on failure none is left behind and
   !> existing files of that name are untouched. Each file is renamed into place when
   !> all are written, PREFIX.h5 last, so its presence marks a complete set.
   subroutine write_results(prefix, deck, res, maps, info, status)
      character(len=*), intent(in) :: prefix
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      !> The pressure and gap maps of the reached load states (solvers/femcod_maps).
      type(state_maps), intent(in) :: maps(:)
      type(run_info), intent(in) :: info
      type(status_type), intent(inout) :: status
      type(string_type), allocatable :: names(:), temps(:)
      character(len=:), allocatable :: figures
      real(dp) :: t0, t1, t2, hdf5_seconds
      integer :: k
      if (status%code /= 0) return
      allocate(names(0), temps(0))
      figures = "auto"
      if (allocated(info%figures)) figures = info%figures
      ! PREFIX.h5 is written first and renamed last (when it exists, the whole set is
      ! complete); the summary is written last, so that it holds the writing's times.
      call wall_clock(t0)
      call write_hdf5(temporary_name(prefix//".h5"), deck, res, info, maps, status)
      call wall_clock(t1)
      hdf5_seconds = t1 - t0
      call add(".history.csv")
      call write_text(temps(size(temps))%s, history_csv(deck, res, info%friction), status)
      call add(".contacts.csv")
      call write_text(temps(size(temps))%s, contacts_csv(deck, res), status)
      if (size(res%states) > 0) then
         call add(".loads.csv")
         call write_text(temps(size(temps))%s, loads_csv(deck, res, maps, info%friction, info%tangential), status)
      end if
      call add(".xdmf")
      call write_text(temps(size(temps))%s, xdmf_text(base_name(prefix)//".h5", deck, res, info%tangential), status)
      call add(".load_approach.svg")
      call write_text(temps(size(temps))%s, svg_plot("femcod: "//deck%label, "approach (nm)", "total load (nN)", &
         res%step_approach(1:res%nsteps), res%step_load(1:res%nsteps), .false., .false.), status)
      call add(".area_load.svg")
      call write_text(temps(size(temps))%s, area_load_svg(deck, res), status)
      do k = 1, size(res%states)
         if (.not. pressure_figure_wanted(res, k, figures)) cycle
         call add(".pressure_"//int_str(k)//".svg")
         call write_text(temps(size(temps))%s, svg_pressure_map("contact pressure at "// &
            sig_str(res%states(k)%load, 6)//" nN (approach "//sig_str(res%states(k)%approach, 4)//" nm, "// &
            int_str(res%states(k)%contacts)//" contacts)", &
            maps(k)%pressure, deck%np*deck%pixel), status)
      end do
      call wall_clock(t2)
      call add(".summary.json")
      call write_text(temps(size(temps))%s, summary_json(prefix, deck, res, maps, info, [hdf5_seconds, t2 - t1]), status)
      call add(".h5")
      call commit_set(names, temps, status)
   contains
      subroutine add(suffix)
         character(len=*), intent(in) :: suffix
         names = [names, string_type(prefix//suffix)]
         temps = [temps, string_type(temporary_name(prefix//suffix))]
      end subroutine add
   end subroutine write_results


   !> Rename every temporary into place, in order; if anything failed before or a
   !> rename fails, remove the temporaries and the files of this set already renamed,
   !> so that a set is there whole or not at all.
   subroutine commit_set(names, temps, status)
      type(string_type), intent(in) :: names(:), temps(:)
      type(status_type), intent(inout) :: status
      integer :: k, m
      if (status%code /= 0) then
         do m = 1, size(temps)
            call remove_file(temps(m)%s)
         end do
         return
      end if
      do k = 1, size(names)
         call atomic_rename(temps(k)%s, names(k)%s, status)
         if (status%code /= 0) then
            do m = 1, size(temps)
               call remove_file(temps(m)%s)
               if (m < k) call remove_file(names(m)%s)
            end do
            return
         end if
      end do
   end subroutine commit_set

   !> Write text files as one set (each to PATH.part, then all renamed into place; on
   !> any failure none is left behind). Used by the study commands.
   subroutine write_file_set(names, texts, status)
      type(string_type), intent(in) :: names(:), texts(:)
      type(status_type), intent(inout) :: status
      type(string_type), allocatable :: temps(:)
      integer :: k
      if (status%code /= 0) return
      allocate(temps(size(names)))
      do k = 1, size(names)
         temps(k)%s = temporary_name(names(k)%s)
         call write_text(temps(k)%s, texts(k)%s, status)
      end do
      call commit_set(names, temps, status)
   end subroutine write_file_set

   !> The result file a temporary name stands for (temporary_name appends ".part").
   function result_name(tmp) result(name)
      character(len=*), intent(in) :: tmp
      character(len=:), allocatable :: name
      integer :: k
      k = index(tmp, ".part", back=.true.)
      name = tmp
      if (k > 1) name = tmp(1:k - 1)
   end function result_name

   subroutine write_text(tmp, text, status)
      character(len=*), intent(in) :: tmp, text
      type(status_type), intent(inout) :: status
      type(status_type) :: st
      call write_bytes(tmp, text, st)
      ! Name the result file, not its temporary.
      if (st%code /= 0 .and. status%code == 0) &
         call set_error(status, st%code, result_name(tmp)//st%message(len(tmp) + 1:))
   end subroutine write_text

   !> PREFIX.history.csv: one row per step; with `friction`, the shear model's columns.
   function history_csv(deck, res, friction) result(text)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      logical, intent(in) :: friction
      character(len=:), allocatable :: text
      type(text_builder) :: b
      integer :: k
      real(dp) :: area_pixel, region
      area_pixel = deck%pixel**2
      region = deck%np**2*area_pixel
      call add_line(b, HISTORY_HEADER//trim(merge(FRICTION_COLUMNS, repeat(" ", len(FRICTION_COLUMNS)), friction)))
      do k = 1, res%nsteps
         call add_line(b, int_str(k)//","//int_str(res%step_contacts(k))//","// &
            format_real(res%step_load(k))//","//format_real(res%step_approach(k))//","// &
            format_real(res%step_contacts(k)*area_pixel)//","//format_real(res%step_contacts(k)*area_pixel/region)// &
            ","//int_str(res%step_above_hardness(k))//","//int_str(step_plastic(res, k))// &
            friction_fields(friction, res%step_friction(k), res%step_load(k), res%step_contacts(k)))
      end do
      text = built_text(b)
   end function history_csv

   !> ",F_t,mu" for the friction columns (F_t nN at load F nN); "" without them.
   function friction_fields(friction, force, load, contacts) result(text)
      logical, intent(in) :: friction
      real(dp), intent(in) :: force, load
      integer, intent(in) :: contacts
      character(len=:), allocatable :: text
      text = ""
      if (friction) text = ","//format_real(force)//","//format_real(friction_coefficient(force, load, contacts))
   end function friction_fields

   !> ",Q,delta,stick,stick_fraction" of a state's tangential step (x components; "" when
   !> the state has none).
   function tangential_fields(s, tangential) result(text)
      type(load_state), intent(in) :: s
      logical, intent(in) :: tangential
      character(len=:), allocatable :: text
      text = ""
      if (.not. tangential) return
      if (.not. allocated(s%stick)) then
         text = ",0,0,0,nan"
         return
      end if
      text = ","//format_real(s%tangential_force(1))//","//format_real(s%tangential_shift(1))//","// &
         int_str(count(s%stick))//","//format_real(real(count(s%stick), dp)/max(size(s%stick), 1))
   end function tangential_fields

   !> The pixels at the hardness after step k (0 without the plastic cap).
   pure integer function step_plastic(res, k)
      type(contact_result), intent(in) :: res
      integer, intent(in) :: k
      step_plastic = 0
      if (allocated(res%step_plastic)) then
         if (k <= size(res%step_plastic)) step_plastic = res%step_plastic(k)
      end if
   end function step_plastic

   !> PREFIX.contacts.csv: the contact pixels and their forces at the reported load.
   function contacts_csv(deck, res) result(text)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      character(len=:), allocatable :: text
      character(len=*), parameter :: header = CONTACTS_HEADER
      character(len=24), allocatable :: force(:), pressure(:)
      integer, allocatable :: nf(:), np(:)
      integer(i8), allocatable :: ends(:)
      character(len=20) :: ti, tj, ts
      integer :: k, ni, nj, ns
      integer(i8) :: at
      call format_reals(res%contact_force, force, nf)
      call format_reals(res%contact_force/deck%pixel**2, pressure, np)
      ! Each row's end in the text from the lengths of its numbers, then every row
      ! written at its place, in parallel (fixed-length buffers only: see
      ! shortest_decimal).
      allocate(ends(0:size(res%contact_i)))
      ends(0) = len(header) + 1
      do k = 1, size(res%contact_i)
         ends(k) = ends(k - 1) + digits_of(res%contact_i(k)) + digits_of(res%contact_j(k)) + &
            digits_of(res%contact_step(k)) + nf(k) + np(k) + 5
      end do
      allocate(character(len=ends(size(res%contact_i))) :: text)
      text(1:len(header) + 1) = header//new_line("a")
      !$omp parallel do private(k, ti, tj, ts, ni, nj, ns, at) schedule(static)
      do k = 1, size(res%contact_i)
         call integer_text(int(res%contact_i(k), i8), ti, ni)
         call integer_text(int(res%contact_j(k), i8), tj, nj)
         call integer_text(int(res%contact_step(k), i8), ts, ns)
         at = ends(k - 1)
         text(at + 1:ends(k)) = ti(1:ni)//","//tj(1:nj)//","//ts(1:ns)//","//force(k)(1:nf(k))//","// &
            pressure(k)(1:np(k))//new_line("a")
      end do
      !$omp end parallel do
   contains
      !> The characters of the integer n in decimal.
      pure integer function digits_of(n)
         integer, intent(in) :: n
         integer :: m
         digits_of = merge(2, 1, n < 0)
         m = abs(n)
         do while (m >= 10)
            m = m/10
            digits_of = digits_of + 1
         end do
      end function digits_of
   end function contacts_csv

   !> PREFIX.loads.csv: the states at the requested loads that were reached; with
   !> `friction`, the shear model's columns.
   function loads_csv(deck, res, maps, friction, tangential) result(text)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      type(state_maps), intent(in) :: maps(:)
      logical, intent(in) :: friction, tangential
      character(len=:), allocatable :: text
      type(text_builder) :: b
      integer :: k
      real(dp) :: area_pixel, region
      area_pixel = deck%pixel**2
      region = deck%np**2*area_pixel
      call add_line(b, LOADS_HEADER//trim(merge(FRICTION_COLUMNS, repeat(" ", len(FRICTION_COLUMNS)), friction))// &
         trim(merge(TANGENTIAL_COLUMNS, repeat(" ", len(TANGENTIAL_COLUMNS)), tangential))//PATCH_COLUMNS)
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         associate(s => res%states(k))
            call add_line(b, format_real(s%load)//","//format_real(s%approach)//","// &
               int_str(s%contacts)//","//format_real(s%contacts*area_pixel)//","// &
               format_real(s%contacts*area_pixel/region)//","//format_real(s%max_pressure)//","// &
               int_str(s%n_above_hardness)//","//int_str(s%n_plastic)//","//format_real(s%plastic_volume)// &
               friction_fields(friction, s%friction, s%load, s%contacts)//tangential_fields(s, tangential)// &
               ","//int_str(maps(k)%patches%count4)//","//int_str(maps(k)%patches%count8))
         end associate
      end do
      text = built_text(b)
   end function loads_csv

   !> The HDF5 file (schema in doc/results.md).
   subroutine write_hdf5(tmp, deck, res, info, maps, status)
      character(len=*), intent(in) :: tmp
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      type(run_info), intent(in) :: info
      type(state_maps), intent(in) :: maps(:)
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      type(status_type) :: local
      character(len=:), allocatable :: g, scene
      real(dp) :: area_pixel, region, exponent, prefactor
      type(cg_state_diagnostics) :: work
      integer :: k, n
      if (status%code /= 0) return
      n = res%nsteps
      area_pixel = deck%pixel**2
      region = deck%np**2*area_pixel
      call h5_create(tmp, file, local)
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
      call h5_group(file, "/surfaces", local)
      call h5_write(file, "/surfaces/lower", deck%lower, "nm", local, compress=mostly_zero(deck%lower))
      call h5_write(file, "/surfaces/upper", deck%upper, "nm", local, compress=mostly_zero(deck%upper))
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
      call h5_group(file, "/loads", local)
      do k = 1, size(res%states)
         if (.not. res%states(k)%reached) cycle
         g = load_group(k, size(res%states))
         associate(s => res%states(k))
            call h5_group(file, g, local)
            call h5_attribute(file, g, "index", k, local)
            call h5_attribute(file, g, "load_nN", s%load, local)
            call h5_attribute(file, g, "approach_nm", s%approach, local)
            call h5_attribute(file, g, "contacts", s%contacts, local)
            call h5_attribute(file, g, "area_nm2", s%contacts*area_pixel, local)
            call h5_attribute(file, g, "max_pressure_GPa", s%max_pressure, local)
            call h5_attribute(file, g, "n_above_hardness", s%n_above_hardness, local)
            call h5_attribute(file, g, "n_plastic", s%n_plastic, local)
            call h5_attribute(file, g, "plastic_volume_nm3", s%plastic_volume, local)
            if (info%solver == "cg") then
               work = cg_work(res, k)
               call h5_attribute(file, g, "cg_iterations", work%iterations, local)
               call h5_attribute(file, g, "cg_residual", work%residual, local)
               call h5_attribute(file, g, "cg_penetration_nm", work%penetration, local)
               call h5_attribute(file, g, "cg_contact_gap_nm", work%contact_gap, local)
               call h5_attribute(file, g, "cg_load_error", work%load_error, local)
               call h5_attribute(file, g, "approach_error_bound_nm", work%approach_bound, local)
            end if
            if (info%tangential) call write_tangential(file, g, deck, s, local)
            if (info%friction) then
               call h5_attribute(file, g, "friction_nN", s%friction, local)
               call h5_attribute(file, g, "friction_coefficient", friction_coefficient(s%friction, s%load, s%contacts), local)
            end if
            if (has_adhesion(info)) then
               call h5_attribute(file, g, "attractive_pixels", s%attractive, local)
               call h5_attribute(file, g, "attractive_load_nN", s%attractive_load, local)
               call h5_attribute(file, g, "mean_gap_nm", s%mean_gap, local)
               call h5_attribute(file, g, "jump", s%jump, local)
            end if
            call write_patches(file, g, maps(k)%patches, local)
            call h5_write(file, g//"/pressure", maps(k)%pressure, "GPa", local, &
               compress=mostly_zero(maps(k)%pressure))
            call h5_write(file, g//"/gap", maps(k)%gap, "nm", local, compress=mostly_zero(maps(k)%gap))
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

   !> area = prefactor * load^exponent, least squares in log-log over the steps with
   !> positive load; NaN for both when fewer than two (no fit: null in the summary file,
   !> where 0, 0 read as a fit).
   subroutine area_fit(deck, res, exponent, prefactor)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      real(dp), intent(out) :: exponent, prefactor
      logical, allocatable :: keep(:)
      exponent = ieee_value(exponent, ieee_quiet_nan)
      prefactor = exponent
      if (res%nsteps < 2) return
      keep = res%step_load(1:res%nsteps) > 0
      if (count(keep) < 2) return
      call power_law_fit(pack(res%step_load(1:res%nsteps), keep), &
         pack(res%step_contacts(1:res%nsteps)*deck%pixel**2, keep), exponent, prefactor)
   end subroutine area_fit

   function area_load_svg(deck, res) result(svg)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      character(len=:), allocatable :: svg
      real(dp) :: exponent, prefactor
      real(dp), allocatable :: area(:)
      call area_fit(deck, res, exponent, prefactor)
      area = res%step_contacts(1:res%nsteps)*deck%pixel**2
      if (prefactor > 0) then
         svg = svg_plot("contact area against load: "//deck%label, "total load (nN)", "contact area (nm^2)", &
            res%step_load(1:res%nsteps), area, .true., .true., exponent, prefactor)
      else
         svg = svg_plot("contact area against load: "//deck%label, "total load (nN)", "contact area (nm^2)", &
            res%step_load(1:res%nsteps), area, .true., .true.)
      end if
   end function area_load_svg

   !> The group of requested load k of n: /loads/001 ... (at least three digits, so
   !> that the names sort as numbers).
   function load_group(k, n) result(g)
      integer, intent(in) :: k, n
      character(len=:), allocatable :: g
      integer :: width
      width = max(3, len(int_str(n)))
      g = int_str(k)
      g = "/loads/"//repeat("0", width - len(g))//g
   end function load_group

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

   !> A state's tangential step in its load group: the shift (nm, x and y), the force (nN),
   !> the sticking pixels, gross sliding, the iterations and residual as attributes; the
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
      call h5_attribute(file, g, "tangential_force_nN", s%tangential_force(1), status)
      call h5_attribute(file, g, "tangential_force_y_nN", s%tangential_force(2), status)
      call h5_attribute(file, g, "tangential_shift_nm", s%tangential_shift(1), status)
      call h5_attribute(file, g, "tangential_shift_y_nm", s%tangential_shift(2), status)
      call h5_attribute(file, g, "stick_contacts", int(sum(map(:, :, 3))), status)
      call h5_attribute(file, g, "stick_area_nm2", sum(map(:, :, 3))*deck%pixel**2, status)
      call h5_attribute(file, g, "gross_sliding", merge(1, 0, s%sliding), status)
      call h5_attribute(file, g, "tangential_iterations", s%tangential_iterations, status)
      call h5_attribute(file, g, "tangential_residual", s%tangential_residual, status)
      call h5_write(file, g//"/shear_x", map(:, :, 1), "GPa", status, compress=mostly_zero(map(:, :, 1)))
      call h5_write(file, g//"/shear_y", map(:, :, 2), "GPa", status, compress=mostly_zero(map(:, :, 2)))
      call h5_write(file, g//"/stick", map(:, :, 3), "1", status, compress=mostly_zero(map(:, :, 3)))
      call h5_write(file, g//"/slip", map(:, :, 4), "1", status, compress=mostly_zero(map(:, :, 4)))
   end subroutine write_tangential

   !> The contacts that stick after a state's tangential step (0 without one).
   pure integer function stick_count(s)
      type(load_state), intent(in) :: s
      stick_count = 0
      if (allocated(s%stick)) stick_count = count(s%stick)
   end function stick_count

   !> Whether at least half of a map is zero: such maps (the pressure below half contact, a
   !> flat surface, no plastic displacement) are stored deflated (h5_write's compress), a
   !> small fraction of their size, and sooner than written whole.
   pure logical function mostly_zero(map)
      real(dp), intent(in) :: map(:, :)
      mostly_zero = 2*count(map == 0) >= size(map)
   end function mostly_zero

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

   !> /run's datasets of the solver's checks: the event path's (zeros for cg) and the
   !> legacy solver's conditioning (its defaults, pivot loss 1 and condition 0, for the
   !> others), the same datasets for every solver.
   !> A load group's contact patches: the counts and the perimeter-area fit as attributes,
   !> each patch's area and perimeter as datasets (when there are patches).
   subroutine write_patches(file, g, patches, local)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: g
      type(contact_patches), intent(in) :: patches
      type(status_type), intent(inout) :: local
      real(dp) :: exponent, prefactor
      call h5_attribute(file, g, "patches_4", patches%count4, local)
      call h5_attribute(file, g, "patches_8", patches%count8, local)
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

   !> The file name without its directory.
   function base_name(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      name = path(index(path, "/", back=.true.) + 1:)
   end function base_name

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

   !> The run's boundary ("free" unless the caller says otherwise).
   pure function run_boundary(info) result(text)
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      text = "free"
      if (allocated(info%boundary)) text = info%boundary
   end function run_boundary
   !> Whether the run had an adhesion law.
   pure logical function has_adhesion(info)
      type(run_info), intent(in) :: info
      has_adhesion = .false.
      if (allocated(info%adhesion)) has_adhesion = info%adhesion /= "none"
   end function has_adhesion

   !> The summary file's adhesion fields (a line each, with the comma), or nothing.
   function adhesion_json(info) result(text)
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      text = ""
      if (has_adhesion(info)) text = '  "adhesion": {"law": '//json_string(info%adhesion)// &
         ', "work_of_adhesion_J_m2": '//json_number(info%work)//', "range_nm": '//json_number(info%range)//'},'// &
         new_line("a")
   end function adhesion_json
end module femcod_results
