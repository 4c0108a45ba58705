!> `femcod report`'s pages, built from the files a run or a study wrote (never from a
!> solver's memory, so a report can be made again, anywhere the files are copied):
!> - a run (PREFIX.summary.json and PREFIX.h5): the run, the load-approach and area-load
!>   curves (with Hertz' or the flat punch's closed form when the deck is a mkdeck sphere
!>   or circular punch), the states' table and maps, the contact patches, the checks,
!>   the timings and every value of the summary;
!> - a study (PREFIX.resolution.json, .summits.json, .multiscale.json, .refine.json):
!>   its tables and the figures it wrote;
!> - a results directory: every run's row in one sortable table, all area-load curves in
!>   one figure, the failed decks with their messages (PREFIX.failed.json of a batch).
!> Maps are read from PREFIX.h5 and drawn as the run's own figures are (femcod_svg: maps
!> above 1024^2 by blocks, each block's largest pressure or smallest gap).
module femcod_report
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_strings, only: string_type, int_str, sig_str, xml_escape, text_builder, add_text, built_text, count_text, &
      ends_with
   use femcod_files, only: read_file, path_exists, directory_names, base_name, write_file
   use femcod_json_reader, only: json_leaf, read_json_leaves, leaf_text, leaf_real, leaf_count, leaf_index
   use femcod_html, only: html_page, inline_svg, leaf_cell, leaf_rows_table, members_table, array_table, &
      every_value_table, array_names
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_read, h5_exists
   use femcod_svg, only: svg_plot, svg_multi_plot, svg_series, add_series, svg_map, svg_pressure_map, &
      svg_stick_slip_map, BLOCK_LARGEST, BLOCK_SMALLEST
   use femcod_analytic, only: hertz_approach
   implicit none
   private
   public :: report_page, batch_page, STUDY_KINDS, study_figures, REPORT_MAP_STATES

   !> A report draws the maps of at most this many states, spread evenly from the first
   !> reached to the last (all of them in PREFIX.h5).
   integer, parameter :: REPORT_MAP_STATES = 10
   !> The studies a report reads (PREFIX.<kind>.json).
   character(len=*), parameter :: STUDY_KINDS(4) = [character(len=10) :: "resolution", "summits", "multiscale", "refine"]
   character(len=1), parameter :: nl = new_line("a")

contains

   !> The figures (PREFIX.<name>.svg) a study writes, as its command names them.
   function study_figures(kind) result(names)
      character(len=*), intent(in) :: kind
      type(string_type), allocatable :: names(:)
      select case (kind)
      case ("resolution")
         names = [string_type("load_displacement"), string_type("area_displacement"), string_type("area_pressure"), &
            string_type("richardson"), string_type("hardness")]
      case ("summits")
         names = [string_type("summit_density"), string_type("summit_height"), string_type("summit_radius"), &
            string_type("psd"), string_type("structure")]
      case default
         names = [string_type(kind)]
      end select
   end function study_figures

   !> The page of the results under `prefix`: a run's when PREFIX.summary.json exists,
   !> else a study's; an error naming what was looked for when there is neither.
   subroutine report_page(prefix, html, status)
      character(len=*), intent(in) :: prefix
      character(len=:), allocatable, intent(out) :: html
      type(status_type), intent(inout) :: status
      integer :: k
      html = ""
      if (path_exists(prefix//".summary.json")) then
         call run_page(prefix, html, status)
         return
      end if
      do k = 1, size(STUDY_KINDS)
         if (.not. path_exists(prefix//"."//trim(STUDY_KINDS(k))//".json")) cycle
         call study_page(prefix, trim(STUDY_KINDS(k)), html, status)
         return
      end do
      call set_error(status, STATUS_BAD_INPUT, prefix//".summary.json: no such file (femcod report PREFIX reads "// &
         "what `femcod run -o PREFIX` wrote, or a study's PREFIX.resolution.json, .summits.json, .multiscale.json "// &
         "or .refine.json; femcod report DIR reads a directory of results)")
   end subroutine report_page

   !> A JSON file's leaves (an error names the file and line).
   subroutine json_file_leaves(path, leaves, status)
      character(len=*), intent(in) :: path
      type(json_leaf), allocatable, intent(out) :: leaves(:)
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: text
      allocate(leaves(0))
      call read_file(path, "femcod's JSON results", text, status)
      if (status%code /= 0) return
      call read_json_leaves(text, path, leaves, status)
   end subroutine json_file_leaves

   subroutine run_page(prefix, html, status)
      character(len=*), intent(in) :: prefix
      character(len=:), allocatable, intent(out) :: html
      type(status_type), intent(inout) :: status
      type(json_leaf), allocatable :: leaves(:)
      type(h5_file) :: file
      type(text_builder) :: b
      character(len=:), allocatable :: label, name
      integer :: k
      html = ""
      call json_file_leaves(prefix//".summary.json", leaves, status)
      if (status%code /= 0) return
      call h5_open(prefix//".h5", file, status, STATUS_BAD_INPUT)
      if (status%code /= 0) return
      label = leaf_text(leaves, "scene.label")
      call add_text(b, "<h1>femcod report: "//xml_escape(base_name(prefix))//"</h1>"//nl//"<p>"//xml_escape(label)// &
         "</p>"//nl//'<nav><a href="#run">Run</a><a href="#curves">Curves</a><a href="#states">States</a>'// &
         '<a href="#patches">Patches</a><a href="#checks">Checks</a><a href="#times">Times</a>'// &
         '<a href="#every-value">Every value</a></nav>'//nl)
      call add_text(b, run_section(leaves))
      call add_text(b, curves_section(file, leaves, status))
      call add_text(b, states_section(file, leaves, status))
      call add_text(b, patches_section(file, leaves, status))
      call add_text(b, '<section id="checks"><h2>The solver'//"'"//'s checks</h2>'//nl//members_table(leaves, "checks"))
      if (members_table(leaves, "solver_details") /= "") call add_text(b, "<h3>The solver's work</h3>"//nl// &
         members_table(leaves, "solver_details"))
      block
         type(string_type), allocatable :: arrays(:)
         arrays = array_names(leaves, "solver_details")
         do k = 1, size(arrays)
            name = "solver_details."//arrays(k)%s
            call add_text(b, "<h3>"//xml_escape(name)//"</h3>"//nl//array_table(leaves, name, .false.))
         end do
      end block
      call add_text(b, "</section>"//nl//'<section id="times"><h2>Times (s) and memory (bytes)</h2>'//nl// &
         members_table(leaves, "timings_s")//members_table(leaves, "memory_bytes")//"</section>"//nl)
      call add_text(b, every_value_table(leaves, base_name(prefix)//".summary.json"))
      call h5_close(file, status)
      if (status%code /= 0) return
      html = html_page("femcod report: "//base_name(prefix)//" ("//label//")", built_text(b), .true.)
   end subroutine run_page

   !> The run: what was solved, by which build, where, when and how it ended.
   function run_section(leaves) result(html)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=:), allocatable :: html
      character(len=:), allocatable :: stopped, ended
      stopped = leaf_text(leaves, "stopped")
      if (stopped == "interrupted") then
         ended = "interrupted by a stop signal: the states finished before it (femcod run --restart completes it)"
      else
         ended = "completed (exit status 0): "//stopped
      end if
      html = '<section id="run"><h2>Run</h2>'//nl//"<p>"//xml_escape(ended)//"</p>"//nl// &
         leaf_rows_table(leaves, [string_type("scene.label"), string_type("command_line"), &
         string_type("femcod_version"), string_type("host"), string_type("started"), string_type("finished"), &
         string_type("solver"), string_type("boundary"), string_type("stopped"), string_type("steps"), &
         string_type("scene.NP"), string_type("scene.pixel_nm"), string_type("scene.MAXCONT"), &
         string_type("kappa_scale.composite_modulus_GPa"), string_type("kappa_scale.rms_slope"), &
         string_type("wall_time_s"), string_type("memory_bytes.peak")], &
         [string_type("deck"), string_type("command line"), string_type("femcod version"), string_type("machine"), &
         string_type("started"), string_type("finished"), string_type("solver"), string_type("boundary"), &
         string_type("stopped"), string_type("steps"), string_type("NP (pixels a side)"), &
         string_type("pixel (nm)"), string_type("MAXCONT"), string_type("E* (GPa)"), &
         string_type("rms slope h'_rms"), string_type("solve wall time (s)"), string_type("peak memory (bytes)")])
      html = html//string_list(leaves, "warnings", "Warnings", "failed")//string_list(leaves, "model", "The model", "")
      html = html//"<h3>Young's modulus (GPa)</h3>"//nl//members_table(leaves, "scene.young_GPa")// &
         "<h3>Poisson's ratio</h3>"//nl//members_table(leaves, "scene.poisson")//"</section>"//nl
   end function run_section

   !> The strings of the array at `path` as a list under a heading ("" when empty).
   function string_list(leaves, path, heading, class) result(html)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: path, heading, class
      character(len=:), allocatable :: html
      integer :: k, n
      html = ""
      n = leaf_count(leaves, path)
      if (n == 0) return
      if (class /= "") then
         html = '<h3 class="'//class//'">'//heading//"</h3>"//nl//"<ul>"//nl
      else
         html = "<h3>"//heading//"</h3>"//nl//"<ul>"//nl
      end if
      do k = 0, n - 1
         html = html//"<li>"//xml_escape(leaf_text(leaves, path//"["//int_str(k)//"]"))//"</li>"//nl
      end do
      html = html//"</ul>"//nl
   end function string_list

   !> The closed form a mkdeck scene has, from its label: "rigid sphere R=<r> nm" (Hertz)
   !> or "circular rigid punch R=<r> nm" (the flat punch, P = 2 a E* delta). `kind` is
   !> "" for other scenes.
   subroutine scene_reference(label, kind, radius)
      character(len=*), intent(in) :: label
      character(len=:), allocatable, intent(out) :: kind
      real(dp), intent(out) :: radius
      integer :: at, ends, ios
      kind = ""
      radius = 0
      if (index(label, "rigid sphere R=") == 1) then
         kind = "Hertz"
      else if (index(label, "circular rigid punch R=") == 1) then
         kind = "flat punch"
      else
         return
      end if
      at = index(label, "R=") + 2
      ends = index(label(at:), " nm")
      ios = 1
      if (ends > 1) read(label(at:at + ends - 2), *, iostat=ios) radius
      if (ios /= 0 .or. .not. radius > 0) kind = ""
   end subroutine scene_reference

   !> The load-approach curve (with the scene's closed form) and the area-load curve
   !> with its power-law fit, from /history of PREFIX.h5.
   function curves_section(file, leaves, status) result(html)
      type(h5_file), intent(in) :: file
      type(json_leaf), intent(in) :: leaves(:)
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: html
      real(dp), allocatable :: load(:), approach(:), area(:), model(:)
      type(svg_series), allocatable :: series(:)
      character(len=:), allocatable :: kind, label
      real(dp) :: radius, estar, exponent, prefactor
      integer :: k
      html = '<section id="curves"><h2>Load, approach and contact area</h2>'//nl
      if (h5_exists(file, "/history")) then
         call h5_read(file, "/history/load", load, status, STATUS_BAD_INPUT)
         call h5_read(file, "/history/approach", approach, status, STATUS_BAD_INPUT)
         call h5_read(file, "/history/area", area, status, STATUS_BAD_INPUT)
         if (status%code /= 0) return
      else
         ! femcod-mpi's sets keep no history: the reached states make the curves.
         call state_curves(leaves, load, approach, area)
      end if
      label = leaf_text(leaves, "scene.label")
      call add_series(series, "femcod", approach, load)
      call scene_reference(label, kind, radius)
      estar = leaf_real(leaves, "kappa_scale.composite_modulus_GPa", 0.0_dp)
      if (kind /= "" .and. estar > 0) then
         allocate(model(size(load)))
         do k = 1, size(load)
            if (kind == "Hertz") then
               model(k) = hertz_approach(max(load(k), 0.0_dp), radius, estar)
            else
               model(k) = max(load(k), 0.0_dp)/(2*radius*estar)
            end if
         end do
         call add_series(series, kind//" (R = "//sig_str(radius, 6)//" nm, E* = "//sig_str(estar, 6)//" GPa)", &
            model, load, dashed=.true., markers=.false.)
      end if
      html = html//'<div class="figures">'//inline_svg(svg_multi_plot("load against approach", "approach (nm)", &
         "total load (nN)", series, .false., .false.))
      exponent = leaf_real(leaves, "area_load_fit.exponent", 0.0_dp)
      prefactor = leaf_real(leaves, "area_load_fit.prefactor_nm2", 0.0_dp)
      if (prefactor > 0) then
         html = html//inline_svg(svg_plot("contact area against load", "total load (nN)", "contact area (nm^2)", &
            load, area, .true., .true., exponent, prefactor))
      else
         html = html//inline_svg(svg_plot("contact area against load", "total load (nN)", "contact area (nm^2)", &
            load, area, .true., .true.))
      end if
      html = html//"</div>"//nl
      if (kind /= "") html = html//'<p class="note">Dashed: the closed form of the scene ('//kind// &
         ", from the deck's label and the composite modulus E*), approach measured from first touch.</p>"//nl
      html = html//"</section>"//nl
   end function curves_section

   !> Load, approach and area of the reached states (in the order asked).
   subroutine state_curves(leaves, load, approach, area)
      type(json_leaf), intent(in) :: leaves(:)
      real(dp), allocatable, intent(out) :: load(:), approach(:), area(:)
      character(len=:), allocatable :: state
      integer :: k
      allocate(load(0), approach(0), area(0))
      do k = 0, leaf_count(leaves, "loads") - 1
         state = "loads["//int_str(k)//"]"
         if (leaf_index(leaves, state//".hdf5_group") == 0) cycle
         load = [load, leaf_real(leaves, state//".load_nN", 0.0_dp)]
         approach = [approach, leaf_real(leaves, state//".approach_nm", 0.0_dp)]
         area = [area, leaf_real(leaves, state//".area_nm2", 0.0_dp)]
      end do
   end subroutine state_curves

   !> The states: their table, and the maps of up to REPORT_MAP_STATES of them.
   function states_section(file, leaves, status) result(html)
      type(h5_file), intent(in) :: file
      type(json_leaf), intent(in) :: leaves(:)
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: html
      integer, allocatable :: reached(:)
      integer :: n, k, m, pick
      html = '<section id="states"><h2>States</h2>'//nl
      n = leaf_count(leaves, "loads")
      if (n == 0) then
         html = html//"<p>No state was requested (--loads or --approach): the history above is the result, "// &
            "and the last step's contacts (PREFIX.h5 /contacts) its map.</p>"//nl//last_step_map(file, leaves, status)// &
            "</section>"//nl
         return
      end if
      html = html//array_table(leaves, "loads", .true.)
      allocate(reached(0))
      do k = 0, n - 1
         if (leaf_index(leaves, "loads["//int_str(k)//"].hdf5_group") > 0) reached = [reached, k]
      end do
      m = size(reached)
      if (m > REPORT_MAP_STATES) html = html//'<p class="note">Maps of '//int_str(REPORT_MAP_STATES)//" of the "// &
         int_str(m)//" reached states, spread evenly from the first to the last (every map is in the HDF5 file).</p>"//nl
      do k = 1, min(m, REPORT_MAP_STATES)
         pick = k
         if (m > REPORT_MAP_STATES) pick = 1 + nint(real((k - 1)*(m - 1), dp)/(REPORT_MAP_STATES - 1))
         html = html//state_maps(file, leaves, reached(pick), status)
         if (status%code /= 0) return
      end do
      html = html//"</section>"//nl
   end function states_section

   !> The pressure map of the last step's contacts (/contacts: 1-based rows and columns,
   !> pressures in GPa), for a run without requested states.
   function last_step_map(file, leaves, status) result(html)
      type(h5_file), intent(in) :: file
      type(json_leaf), intent(in) :: leaves(:)
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: html
      integer, allocatable :: i(:), j(:)
      real(dp), allocatable :: pressure(:), map(:, :)
      integer :: np, k
      html = ""
      if (.not. h5_exists(file, "/contacts/pressure")) return
      call h5_read(file, "/contacts/i", i, status, STATUS_BAD_INPUT)
      call h5_read(file, "/contacts/j", j, status, STATUS_BAD_INPUT)
      call h5_read(file, "/contacts/pressure", pressure, status, STATUS_BAD_INPUT)
      if (status%code /= 0) return
      np = nint(leaf_real(leaves, "scene.NP", 0.0_dp))
      allocate(map(np, np), source=0.0_dp)
      do k = 1, size(pressure)
         if (min(i(k), j(k)) < 1 .or. max(i(k), j(k)) > np) cycle
         map(i(k), j(k)) = pressure(k)
      end do
      html = '<div class="figures">'//inline_svg(svg_pressure_map("contact pressure at the last step, "// &
         sig_str(leaf_real(leaves, "last_step.load_nN", 0.0_dp), 6)//" nN ("//leaf_text(leaves, "last_step.contacts")// &
         " contacts)", map, np*leaf_real(leaves, "scene.pixel_nm", 0.0_dp)))//"</div>"//nl
   end function last_step_map

   !> The maps of state `k` (0-based in loads[]): pressure and gap, plastic
   !> displacement and stick/slip where PREFIX.h5 has them.
   function state_maps(file, leaves, k, status) result(html)
      type(h5_file), intent(in) :: file
      type(json_leaf), intent(in) :: leaves(:)
      integer, intent(in) :: k
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: html
      character(len=:), allocatable :: group, at, state
      real(dp), allocatable :: map(:, :), slip(:, :)
      real(dp) :: side
      state = "loads["//int_str(k)//"]"
      group = leaf_text(leaves, state//".hdf5_group")
      side = leaf_real(leaves, "scene.NP", 0.0_dp)*leaf_real(leaves, "scene.pixel_nm", 0.0_dp)
      at = " at "//sig_str(leaf_real(leaves, state//".load_nN", 0.0_dp), 6)//" nN (approach "// &
         sig_str(leaf_real(leaves, state//".approach_nm", 0.0_dp), 4)//" nm, "// &
         leaf_text(leaves, state//".contacts")//" contacts)"
      html = "<h3>State "//int_str(k + 1)//at//"</h3>"//nl//'<div class="figures">'
      call h5_read(file, group//"/pressure", map, status, STATUS_BAD_INPUT)
      if (status%code /= 0) return
      html = html//inline_svg(svg_pressure_map("contact pressure"//at, map, side))
      call h5_read(file, group//"/gap", map, status, STATUS_BAD_INPUT)
      if (status%code /= 0) return
      html = html//inline_svg(svg_map("gap"//at, map, side, "nm", "gap", BLOCK_SMALLEST, .false.))
      if (h5_exists(file, group//"/plastic_displacement")) then
         call h5_read(file, group//"/plastic_displacement", map, status, STATUS_BAD_INPUT)
         if (status%code /= 0) return
         html = html//inline_svg(svg_map("plastic displacement"//at, map, side, "nm", "plastic displacement", &
            BLOCK_LARGEST, .true.))
      end if
      if (h5_exists(file, group//"/stick") .and. h5_exists(file, group//"/slip")) then
         call h5_read(file, group//"/stick", map, status, STATUS_BAD_INPUT)
         call h5_read(file, group//"/slip", slip, status, STATUS_BAD_INPUT)
         if (status%code /= 0) return
         html = html//inline_svg(svg_stick_slip_map("stick and slip"//at, map, slip, side))
      end if
      html = html//"</div>"//nl
   end function state_maps

   !> The contact patches (8-connected): their number against load, and at the last
   !> reached state their size distribution and perimeter against area.
   function patches_section(file, leaves, status) result(html)
      type(h5_file), intent(in) :: file
      type(json_leaf), intent(in) :: leaves(:)
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: html
      real(dp), allocatable :: load(:), count(:), area(:), perimeter(:), edges(:), number(:)
      character(len=:), allocatable :: group, state
      integer :: n, k, last, bins, b
      html = '<section id="patches"><h2>Contact patches</h2>'//nl
      n = leaf_count(leaves, "loads")
      allocate(load(0), count(0))
      last = -1
      do k = 0, n - 1
         state = "loads["//int_str(k)//"]"
         if (leaf_index(leaves, state//".patches_8") == 0) cycle
         load = [load, leaf_real(leaves, state//".load_nN", 0.0_dp)]
         count = [count, leaf_real(leaves, state//".patches_8", 0.0_dp)]
         if (leaf_index(leaves, state//".hdf5_group") > 0) last = k
      end do
      if (last < 0) then
         html = html//"<p>No state with its patches (they are counted at the requested states).</p></section>"//nl
         return
      end if
      group = leaf_text(leaves, "loads["//int_str(last)//"].hdf5_group")
      allocate(area(0), perimeter(0))
      if (h5_exists(file, group//"/patch_area_8")) then
         call h5_read(file, group//"/patch_area_8", area, status, STATUS_BAD_INPUT)
         call h5_read(file, group//"/patch_perimeter_8", perimeter, status, STATUS_BAD_INPUT)
         if (status%code /= 0) return
      end if
      html = html//'<div class="figures">'//inline_svg(svg_plot("contact patches (8-connected) against load", &
         "total load (nN)", "patches", load, count, .false., .false.))
      if (size(area) > 0) then
         ! Logarithmic bins, two a decade, from one pixel to the largest patch.
         bins = max(1, ceiling(2*log10(max(maxval(area), 1.0_dp))) + 1)
         edges = [(10.0_dp**(real(b, dp)/2), b = 0, bins)]
         allocate(number(bins))
         do b = 1, bins
            number(b) = count_between(area, edges(b), edges(b + 1))
         end do
         html = html//inline_svg(svg_plot("patch sizes at "//sig_str(leaf_real(leaves, "loads["//int_str(last)// &
            "].load_nN", 0.0_dp), 6)//" nN (two bins a decade)", "patch area (pixels, bin's lower edge)", &
            "patches in the bin", edges(1:bins), number, .true., .true.))
         html = html//inline_svg(svg_plot("patch perimeter against area", "patch area (pixels)", &
            "perimeter (pixel sides)", sorted_by(area, area), sorted_by(perimeter, area), .true., .true.))
      end if
      if (h5_exists(file, group//"/patch_area_8")) then
         html = html//"</div>"//nl//'<p class="note">'//int_str(size(area))//" patches at state "// &
            int_str(last + 1)//" (PREFIX.h5 "//xml_escape(group)//"/patch_area_8 and patch_perimeter_8).</p>"//nl
      else
         html = html//"</div>"//nl//'<p class="note">The patches'//"'"//" sizes are not in this result set "// &
            "(femcod-mpi keeps their counts).</p>"//nl
      end if
      html = html//"</section>"//nl
   end function patches_section

   pure real(dp) function count_between(values, lo, hi) result(c)
      real(dp), intent(in) :: values(:), lo, hi
      c = real(count(values >= lo .and. values < hi), dp)
   end function count_between

   !> `values` ordered by `key` (insertion sort: one state's patches).
   pure function sorted_by(values, key) result(s)
      real(dp), intent(in) :: values(:), key(:)
      real(dp), allocatable :: s(:), k2(:)
      real(dp) :: v, kv
      integer :: i, j
      s = values
      k2 = key
      do i = 2, size(s)
         v = s(i)
         kv = k2(i)
         j = i - 1
         do while (j >= 1)
            if (k2(j) <= kv) exit
            s(j + 1) = s(j)
            k2(j + 1) = k2(j)
            j = j - 1
         end do
         s(j + 1) = v
         k2(j + 1) = kv
      end do
   end function sorted_by

   !> A study's page: its values and tables (PREFIX.<kind>.json), and its figures.
   subroutine study_page(prefix, kind, html, status)
      character(len=*), intent(in) :: prefix, kind
      character(len=:), allocatable, intent(out) :: html
      type(status_type), intent(inout) :: status
      type(json_leaf), allocatable :: leaves(:)
      type(string_type), allocatable :: figures(:), arrays(:), objects(:)
      type(text_builder) :: b
      character(len=:), allocatable :: svg, tops
      integer :: k, rows
      html = ""
      call json_file_leaves(prefix//"."//kind//".json", leaves, status)
      if (status%code /= 0) return
      call add_text(b, "<h1>femcod "//kind//": "//xml_escape(base_name(prefix))//"</h1>"//nl)
      tops = ""
      do k = 1, size(leaves)
         if (scan(leaves(k)%path, ".[") > 0) cycle
         tops = tops//"<tr><th>"//xml_escape(leaves(k)%path)//"</th>"//leaf_cell(leaves(k))//"</tr>"//nl
      end do
      if (tops /= "") call add_text(b, "<table>"//nl//tops//"</table>"//nl)
      figures = study_figures(kind)
      call add_text(b, "<h2>Figures</h2>"//nl//'<div class="figures">')
      do k = 1, size(figures)
         if (.not. path_exists(prefix//"."//figures(k)%s//".svg")) cycle
         call read_file(prefix//"."//figures(k)%s//".svg", "an SVG figure", svg, status)
         if (status%code /= 0) return
         call add_text(b, inline_svg(svg))
      end do
      call add_text(b, "</div>"//nl//"<h2>Tables</h2>"//nl)
      call outer_paths(leaves, objects, arrays)
      do k = 1, size(objects)
         call add_text(b, "<h3>"//xml_escape(objects(k)%s)//"</h3>"//nl//members_table(leaves, objects(k)%s))
      end do
      do k = 1, size(arrays)
         rows = leaf_count(leaves, arrays(k)%s)
         if (rows <= 40) then
            call add_text(b, "<h3>"//xml_escape(arrays(k)%s)//"</h3>"//nl//array_table(leaves, arrays(k)%s, .true.))
         else
            call add_text(b, "<details><summary>"//xml_escape(arrays(k)%s)//" ("//int_str(rows)//" rows)</summary>"// &
               nl//array_table(leaves, arrays(k)%s, .true.)//"</details>"//nl)
         end if
      end do
      call add_text(b, every_value_table(leaves, base_name(prefix)//"."//kind//".json"))
      html = html_page("femcod "//kind//": "//base_name(prefix), built_text(b), .true.)
   end subroutine study_page

   !> The objects below the top with scalar members of their own (outside arrays), and
   !> the outermost arrays, each once, in document order.
   subroutine outer_paths(leaves, objects, arrays)
      type(json_leaf), intent(in) :: leaves(:)
      type(string_type), allocatable, intent(out) :: objects(:), arrays(:)
      character(len=:), allocatable :: p
      integer :: k, at
      allocate(objects(0), arrays(0))
      do k = 1, size(leaves)
         at = index(leaves(k)%path, "[")
         if (at > 1) then
            p = leaves(k)%path(1:at - 1)
            if (.not. listed(arrays, p)) arrays = [arrays, string_type(p)]
         else if (at == 0) then
            at = index(leaves(k)%path, ".", back=.true.)
            if (at < 2) cycle
            p = leaves(k)%path(1:at - 1)
            if (.not. listed(objects, p)) objects = [objects, string_type(p)]
         end if
      end do
   contains
      pure logical function listed(list, name)
         type(string_type), intent(in) :: list(:)
         character(len=*), intent(in) :: name
         integer :: m
         listed = .false.
         do m = 1, size(list)
            if (list(m)%s == name) listed = .true.
         end do
      end function listed
   end subroutine outer_paths

   !> A results directory at a glance: each run's row (its own page written beside its
   !> results as PREFIX.report.html, listed in `written`, and linked), the area-load
   !> curves of all in one figure, and the failed decks with their messages.
   subroutine batch_page(dir, written, html, status)
      character(len=*), intent(in) :: dir
      type(string_type), allocatable, intent(out) :: written(:)
      character(len=:), allocatable, intent(out) :: html
      type(status_type), intent(inout) :: status
      type(string_type), allocatable :: names(:)
      type(json_leaf), allocatable :: leaves(:)
      type(svg_series), allocatable :: series(:)
      type(text_builder) :: rows, failed
      character(len=:), allocatable :: base, page
      integer :: k, nrun, nfailed
      html = ""
      allocate(written(0))
      call directory_names(dir, names, status)
      if (status%code /= 0) return
      nrun = 0
      nfailed = 0
      do k = 1, size(names)
         if (ends_with(names(k)%s, ".summary.json")) then
            base = names(k)%s(1:len(names(k)%s) - len(".summary.json"))
            call report_page(dir//"/"//base, page, status)
            call write_file(dir//"/"//base//".report.html", page, status)
            call json_file_leaves(dir//"/"//names(k)%s, leaves, status)
            if (status%code /= 0) return
            written = [written, string_type(dir//"/"//base//".report.html")]
            nrun = nrun + 1
            call add_text(rows, '<tr><td data-value="'//xml_escape(base)//'"><a href="'//xml_escape(base)// &
               '.report.html">'//xml_escape(base)//"</a></td>"//batch_cells(leaves)//"</tr>"//nl)
            call add_curve(dir//"/"//base//".h5", base, leaves, series, status)
            if (status%code /= 0) return
         else if (ends_with(names(k)%s, ".failed.json")) then
            call json_file_leaves(dir//"/"//names(k)%s, leaves, status)
            if (status%code /= 0) return
            nfailed = nfailed + 1
            call add_text(failed, "<tr>"//leaf_cell(leaves(max(1, leaf_index(leaves, "deck"))))// &
               leaf_cell(leaves(max(1, leaf_index(leaves, "exit_code"))))// &
               leaf_cell(leaves(max(1, leaf_index(leaves, "message"))))//"</tr>"//nl)
         end if
      end do
      html = "<h1>femcod results: "//xml_escape(dir)//"</h1>"//nl//"<p>"//count_text(nrun, "run")//", "// &
         count_text(nfailed, "failed deck")//". Click a column's head to sort by it.</p>"//nl// &
         '<div class="scroll"><table class="sortable" id="runs"><thead><tr><th>results</th><th>deck</th>'// &
         "<th>solver</th><th>boundary</th><th>stopped</th><th>states</th><th>load (nN)</th>"// &
         "<th>approach (nm)</th><th>contacts</th><th>area fraction</th><th>solve time (s)</th></tr></thead>"//nl// &
         "<tbody>"//nl//built_text(rows)//"</tbody></table></div>"//nl
      if (allocated(series)) html = html//'<div class="figures">'//inline_svg(svg_multi_plot( &
         "contact area against load, every run", "total load (nN)", "contact area (nm^2)", series, .true., .true.))// &
         "</div>"//nl
      if (nfailed > 0) html = html//'<h2 class="failed">Failed decks</h2>'//nl//'<table id="failed"><tr><th>deck'// &
         "</th><th>exit code</th><th>message</th></tr>"//nl//built_text(failed)//"</table>"//nl
      html = html_page("femcod results: "//dir, html, .true.)
   end subroutine batch_page

   !> A run's cells in the batch table: the last state's values (the last requested
   !> one reached, else the history's last step).
   function batch_cells(leaves) result(cells)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=:), allocatable :: cells
      character(len=:), allocatable :: last
      integer :: n, k
      cells = ""
      do k = 1, 4
         cells = cells//cell_of([character(len=11) :: "scene.label", "solver", "boundary", "stopped"], k)
      end do
      n = leaf_count(leaves, "loads")
      cells = cells//'<td class="num" data-value="'//int_str(n)//'">'//int_str(n)//"</td>"
      last = "last_step"
      do k = n - 1, 0, -1
         if (leaf_index(leaves, "loads["//int_str(k)//"].hdf5_group") == 0) cycle
         last = "loads["//int_str(k)//"]"
         exit
      end do
      cells = cells//one(last//".load_nN")//one(last//".approach_nm")//one(last//".contacts")// &
         one(last//".area_fraction")//one("wall_time_s")
   contains
      function cell_of(paths, k) result(c)
         character(len=*), intent(in) :: paths(:)
         integer, intent(in) :: k
         character(len=:), allocatable :: c
         c = one(trim(paths(k)))
      end function cell_of
      function one(path) result(c)
         character(len=*), intent(in) :: path
         character(len=:), allocatable :: c
         integer :: at
         at = leaf_index(leaves, path)
         if (at > 0) then
            c = leaf_cell(leaves(at))
         else
            c = '<td data-value=""></td>'
         end if
      end function one
   end function batch_cells

   !> The area-load curve of a run's /history (femcod-mpi: its states), as one series of the batch figure.
   subroutine add_curve(h5_path, label, leaves, series, status)
      character(len=*), intent(in) :: h5_path, label
      type(json_leaf), intent(in) :: leaves(:)
      type(svg_series), allocatable, intent(inout) :: series(:)
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      real(dp), allocatable :: load(:), area(:), approach(:)
      integer :: n
      call h5_open(h5_path, file, status, STATUS_BAD_INPUT)
      if (h5_exists(file, "/history")) then
         call h5_read(file, "/history/load", load, status, STATUS_BAD_INPUT)
         call h5_read(file, "/history/area", area, status, STATUS_BAD_INPUT)
      else
         call state_curves(leaves, load, approach, area)
      end if
      call h5_close(file, status)
      if (status%code /= 0) return
      ! The plot's eight colours again, dashed, from the ninth run on.
      n = 0
      if (allocated(series)) n = size(series)
      call add_series(series, label, load, area, dashed=n >= 8)
   end subroutine add_curve

end module femcod_report
