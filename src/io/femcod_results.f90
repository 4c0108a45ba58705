!> Result files of a run, written under temporary names and renamed only when all of
!> them are complete, so a failed run leaves no partial result (doc/results.md):
!>   PREFIX.history.csv   step,contacts,load_nN,approach_nm,area_nm2,area_fraction,n_above_hardness
!>   PREFIX.loads.csv     load_nN,approach_nm,contacts,area_nm2,area_fraction,max_pressure_GPa,n_above_hardness
!>   PREFIX.contacts.csv  i,j,step,force_nN,pressure_GPa
!>   PREFIX.h5            /deck /surfaces /history /contacts /loads/<kkk> /mesh /run
!>   PREFIX.xdmf          the maps of PREFIX.h5 on a quadrilateral mesh (ParaView, meshio)
!>   PREFIX.summary.json  what the summary prints, as numbers with units
!>   PREFIX.load_approach.svg, PREFIX.area_load.svg, and per state (--figures) the map
!>   figures PREFIX.pressure_<k>.svg, .gap_<k>.svg, .plastic_<k>.svg, .stick_slip_<k>.svg
module femcod_results
   use femcod_kinds, only: dp
   use femcod_clock, only: wall_clock
   use femcod_status, only: status_type, set_error
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str, sig_str
   use femcod_files, only: atomic_rename, remove_file, temporary_name, write_bytes, base_name
   use femcod_contact_result, only: contact_result
   use femcod_maps, only: state_maps, tangential_step_maps, state_pressure_map
   use femcod_svg, only: svg_plot, svg_pressure_map, svg_map, svg_stick_slip_map, BLOCK_SMALLEST, BLOCK_LARGEST
   use femcod_result_schema, only: run_info, FIGURES_AUTO_LIMIT, HISTORY_HEADER, LOADS_HEADER, CONTACTS_HEADER, &
      FRICTION_COLUMNS, TANGENTIAL_COLUMNS, PATCH_COLUMNS, result_name, area_fit, load_group
   use femcod_results_csv, only: history_csv, contacts_csv, loads_csv
   use femcod_results_hdf5, only: write_hdf5, xdmf_text, stored_fingerprint, read_streamed_gap_map
   use femcod_results_json, only: summary_json
   implicit none
   private
   public :: write_results, run_info, result_files, write_file_set, stored_fingerprint, load_group
   public :: pressure_figure_wanted, FIGURES_AUTO_LIMIT, MAP_FIGURES, figure_name
   public :: HISTORY_HEADER, LOADS_HEADER, CONTACTS_HEADER, FRICTION_COLUMNS, TANGENTIAL_COLUMNS, PATCH_COLUMNS

   !> The map figures of a state k, PREFIX.<kind>_<k>.svg: its pressure and gap maps,
   !> and with the plastic cap and the tangential step the plastic displacement and the
   !> stick and slip maps (doc/results.md).
   character(len=*), parameter :: MAP_FIGURES(4) = [character(len=10) :: "pressure", "gap", "plastic", "stick_slip"]

contains

   !> PREFIX.<kind>_<k>.svg.
   function figure_name(prefix, kind, k) result(name)
      character(len=*), intent(in) :: prefix, kind
      integer, intent(in) :: k
      character(len=:), allocatable :: name
      name = prefix//"."//trim(kind)//"_"//int_str(k)//".svg"
   end function figure_name

   !> The names of every file a run writes for `prefix` (with `nloads` requested loads).
   function result_files(prefix, nloads) result(names)
      character(len=*), intent(in) :: prefix
      integer, intent(in) :: nloads
      type(string_type), allocatable :: names(:)
      integer :: k, m
      character(len=:), allocatable :: name
      allocate(names(0))
      names = [string_type(prefix//".history.csv"), string_type(prefix//".contacts.csv"), &
         string_type(prefix//".h5"), string_type(prefix//".xdmf"), string_type(prefix//".load_approach.svg"), &
         string_type(prefix//".area_load.svg"), string_type(prefix//".summary.json")]
      if (nloads > 0) names = [names, string_type(prefix//".loads.csv")]
      do k = 1, nloads
         do m = 1, size(MAP_FIGURES)
            ! (A named temporary: gfortran 12 fails on the function in the constructor.)
            name = figure_name(prefix, MAP_FIGURES(m), k)
            names = [names, string_type(name)]
         end do
      end do
   end function result_files

   !> Whether state k gets its map figures (MAP_FIGURES, those its run has) under --figures
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
   subroutine write_results(prefix, deck, res, maps, info, status, started)
      character(len=*), intent(in) :: prefix
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      !> The pressure and gap maps of the reached load states (solvers/femcod_maps).
      type(state_maps), intent(in) :: maps(:)
      type(run_info), intent(in) :: info
      type(status_type), intent(inout) :: status
      !> PREFIX.h5's temporary was started before the solve, with the heights
      !> (femcod_results_hdf5's start_result_file); `deck` may have none.
      logical, intent(in), optional :: started
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
      call write_hdf5(temporary_name(prefix//".h5"), deck, res, info, maps, status, started)
      call wall_clock(t1)
      hdf5_seconds = t1 - t0
      call add(".history.csv")
      call write_text(temps(size(temps))%s, history_csv(deck, res, info%friction), status)
      call add(".contacts.csv")
      call write_text(temps(size(temps))%s, contacts_csv(deck, res), status)
      if (size(res%states) > 0) then
         call add(".loads.csv")
         call write_text(temps(size(temps))%s, loads_csv(deck, res, info), status)
      end if
      call add(".xdmf")
      call write_text(temps(size(temps))%s, xdmf_text(base_name(prefix)//".h5", deck, res, info%tangential), status)
      call add(".load_approach.svg")
      call write_text(temps(size(temps))%s, svg_plot("femcod: "//deck%label, "approach (nm)", "total load (nN)", &
         res%step_approach(1:res%nsteps), res%step_load(1:res%nsteps), .false., .false.), status)
      call add(".area_load.svg")
      call write_text(temps(size(temps))%s, area_load_svg(deck, res), status)
      do k = 1, size(res%states)
         if (pressure_figure_wanted(res, k, figures)) call write_map_figures(k)
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

      !> State k's map figures (MAP_FIGURES): pressure and gap, plastic displacement with
      !> the cap, stick and slip with the tangential step.
      subroutine write_map_figures(k)
         integer, intent(in) :: k
         character(len=:), allocatable :: at
         real(dp), allocatable :: step(:, :, :), gap(:, :)
         real(dp) :: side
         side = deck%np*deck%pixel
         at = " at "//sig_str(res%states(k)%load, 6)//" nN (approach "//sig_str(res%states(k)%approach, 4)//" nm, "// &
            int_str(res%states(k)%contacts)//" contacts)"
         call add(".pressure_"//int_str(k)//".svg")
         call write_text(temps(size(temps))%s, svg_pressure_map("contact pressure"//at, &
            state_pressure_map(deck%np, deck%pixel, res%states(k)), side), status)
         call add(".gap_"//int_str(k)//".svg")
         if (maps(k)%gap_in_file) then
            call read_streamed_gap_map(temporary_name(prefix//".h5"), k, size(res%states), gap, status)
            if (status%code == 0) call write_gap_figure(gap, at, side)
         else
            call write_gap_figure(maps(k)%gap, at, side)
         end if
         if (allocated(res%states(k)%plastic)) then
            call add(".plastic_"//int_str(k)//".svg")
            call write_text(temps(size(temps))%s, svg_map("plastic displacement"//at, res%states(k)%plastic, side, &
               "nm", "plastic displacement", BLOCK_LARGEST, .true.), status)
         end if
         if (allocated(res%states(k)%stick)) then
            step = tangential_step_maps(deck%np, deck%pixel, res%states(k))
            call add(".stick_slip_"//int_str(k)//".svg")
            call write_text(temps(size(temps))%s, svg_stick_slip_map("stick and slip"//at, step(:, :, 3), &
               step(:, :, 4), side), status)
         end if
      end subroutine write_map_figures

      subroutine write_gap_figure(gap, at, side)
         real(dp), intent(in) :: gap(:, :), side
         character(len=*), intent(in) :: at
         call write_text(temps(size(temps))%s, svg_map("gap"//at, gap, side, "nm", "gap", BLOCK_SMALLEST, .false.), &
            status)
      end subroutine write_gap_figure
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

   subroutine write_text(tmp, text, status)
      character(len=*), intent(in) :: tmp, text
      type(status_type), intent(inout) :: status
      type(status_type) :: st
      call write_bytes(tmp, text, st)
      ! Name the result file, not its temporary.
      if (st%code /= 0 .and. status%code == 0) &
         call set_error(status, st%code, result_name(tmp)//st%message(len(tmp) + 1:))
   end subroutine write_text

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
end module femcod_results

