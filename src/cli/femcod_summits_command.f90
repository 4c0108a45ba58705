!> `femcod summits`: the summit search, PSD and structure function of the thesis' chapter 3
!> (studies/femcod_summits), their tables and figures.
module femcod_summits_command
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_strings, only: string_type, int_str, sig_str, text_builder, add_line, built_text, format_real
   use femcod_results, only: write_file_set
   use femcod_svg, only: svg_series, svg_multi_plot, add_series
   use femcod_summits, only: summit_statistics, summit_search, default_sizes, profile_psd, summit_power_laws, &
      structure_function, psd_dimension, structure_dimension, summits_storage_bytes
   use femcod_memory, only: available_memory, memory_text, usable_text
   use femcod_help, only: print_lines
   use femcod_options, only: parsed_options, option_help
   use femcod_studies, only: surface_options, summit_plot, check_outputs, study_json, study_heights, surface_table, &
      parse_surface_options, fail_with
   implicit none
   private
   public :: summits_command

contains

   subroutine summits_help()
      write(output_unit, '(a)') &
         "usage: femcod summits FILE [--pixel D] [--sizes 1,2,3,...] [--remove-plane] [-o PREFIX] [--force] [--quiet]", &
         "", &
         "The surface analysis of the thesis, chapter 3. FILE is a deck (its composite roughness: the lower", &
         "surface plus the upper one as it faces it) or a height file: an ASCII matrix (with --pixel D, nm),", &
         "a Gwyddion export, FILE.h5:/dataset, or a NanoScope file FILE[:CHANNEL].", &
         "  Summit search (section 3.2): for each neighbourhood size n the box is d_n = (2n+1) L/N (eq. 3.2);", &
         "  a summit is higher than its 8 neighbours and the highest pixel of its box, searched in the central", &
         "  region common to all sizes; at each summit the least-squares elliptic paraboloid with axes along x", &
         "  and y and its maximum at the summit pixel gives Rx, Ry; the radius is sqrt(Rx Ry). Heights are", &
         "  measured from the image's mean.", &
         "  Profile PSD (eq. 2.12) over rows and columns, fractal dimension D = (5 + slope)/2 (eq. 3.1) fitted", &
         "  from 4/L to 1/(4d); structure function (eq. 2.14), D = 2 - slope/2 (eq. 2.15) from d to L/16.", ""
      call print_lines(option_help(surface_table("summits"), ""))
      write(output_unit, '(a)') "", &
         "outputs: PREFIX.summits.csv  box_nm,n,density_per_um2,mean_height_nm,mean_radius_nm", &
         "         PREFIX.summit_exponents.csv  quantity,exponent,prefactor (power laws against the box in nm)", &
         "         PREFIX.psd.csv  frequency_per_nm,power_nm3;  PREFIX.structure.csv  tau_nm,structure_nm2", &
         "         PREFIX.fractal.csv  method,profile_dimension,surface_dimension,fit_from,fit_to", &
         "         PREFIX.summit_density.svg, .summit_height.svg, .summit_radius.svg (Fig. 3.2), .psd.svg, .structure.svg", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 5 I/O"
   end subroutine summits_help

   !> `femcod summits`.
   subroutine summits_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(surface_options) :: opts
      type(string_type), allocatable :: names(:), texts(:)
      type(parsed_options) :: parsed
      type(status_type) :: status
      type(summit_statistics), allocatable :: stats(:)
      real(dp), allocatable :: z(:, :), freq(:), power(:), tau(:), sf(:), e(:), p(:), box(:)
      type(text_builder) :: b(5)
      type(svg_series), allocatable :: series(:)
      character(len=14), parameter :: quantity(3) = [character(len=14) :: "density", "mean_height", "mean_radius"]
      real(dp) :: d, side, dpsd, slope, dsf, g
      integer(i8) :: need, may
      integer :: k, q, npsd, nsf
      call parse_surface_options("summits", args, opts, parsed, code)
      if (code == -1) then
         code = 0
         call summits_help()
         return
      end if
      if (code /= 0) return
      names = [string_type(opts%prefix//".summits.csv"), string_type(opts%prefix//".summit_exponents.csv"), &
         string_type(opts%prefix//".psd.csv"), string_type(opts%prefix//".structure.csv"), &
         string_type(opts%prefix//".fractal.csv"), string_type(opts%prefix//".summit_density.svg"), &
         string_type(opts%prefix//".summit_height.svg"), string_type(opts%prefix//".summit_radius.svg"), &
         string_type(opts%prefix//".psd.svg"), string_type(opts%prefix//".structure.svg"), &
         string_type(opts%prefix//".summits.json")]
      ! The outputs are checked before the input is read: an input is never an output.
      call check_outputs(names, opts%input, opts%force, status)
      if (status%code == 0) call study_heights(opts%input, opts%pixel, opts%plane, z, d, status, opts%height_unit)
      ! The analysis' memory, checked before it starts (the heights are read).
      if (status%code == 0) then
         need = summits_storage_bytes(size(z, 1), size(z, 2))
         may = available_memory()
         if (may > 0 .and. need > may) call set_error(status, STATUS_NUMERICAL, opts%input//": the analysis of "// &
            int_str(size(z, 1))//" x "//int_str(size(z, 2))//" heights needs about "//memory_text(need)// &
            " besides them (box maxima, summit lists, the structure function's differences), this run may use "// &
            usable_text(may))
      end if
      if (status%code /= 0) then
         call fail_with("summits", status, code)
         return
      end if
      if (size(opts%sizes) == 0) opts%sizes = default_sizes(size(z, 1))
      if (status%code == 0) call summit_search(z, d, opts%sizes, stats, status)
      if (status%code /= 0) then
         call fail_with("summits", status, code)
         return
      end if
      side = size(z, 1)*d
      call profile_psd(z, d, freq, power)
      call psd_dimension(freq, power, 4/side, 1/(4*d), dpsd, slope, npsd)
      call structure_function(z, d, max(1, size(z, 1)/4), tau, sf)
      call structure_dimension(tau, sf, d, side/16, dsf, g, nsf)
      ! A fit range with fewer than two points (grids below 32 pixels) determines nothing:
      ! its CSV fields stay empty and the summary says so.
      if (npsd < 2) write(error_unit, '(a)') "femcod summits: warning: the PSD's fit range 4/L to 1/(4d) holds "// &
         int_str(npsd)//" frequencies on "//int_str(size(z, 1))//" pixels: its dimension is not determined"
      if (nsf < 2) write(error_unit, '(a)') "femcod summits: warning: the structure function's fit range d to L/16 "// &
         "holds "//int_str(nsf)//" lags on "//int_str(size(z, 1))//" pixels: its dimension is not determined"
      call add_line(b(1), "box_nm,n,density_per_um2,mean_height_nm,mean_radius_nm")
      do k = 1, size(stats)
         call add_line(b(1), format_real(stats(k)%box)//","//int_str(stats(k)%n)//","//format_real(stats(k)%density)// &
            ","//format_real(stats(k)%mean_height)//","//format_real(stats(k)%mean_radius))
      end do
      call add_line(b(2), "quantity,exponent,prefactor")
      allocate(e(3), p(3))
      call summit_power_laws(stats, e, p)
      do q = 1, 3
         call add_line(b(2), trim(quantity(q))//","//format_real(e(q))//","//format_real(p(q)))
      end do
      call add_line(b(3), "frequency_per_nm,power_nm3")
      do k = 1, size(freq)
         call add_line(b(3), format_real(freq(k))//","//format_real(power(k)))
      end do
      call add_line(b(4), "tau_nm,structure_nm2")
      do k = 1, size(tau)
         call add_line(b(4), format_real(tau(k))//","//format_real(sf(k)))
      end do
      call add_line(b(5), "method,profile_dimension,surface_dimension,fit_from,fit_to")
      call add_line(b(5), "psd,"//fitted(dpsd, npsd)//","//fitted(dpsd + 1, npsd)//","//format_real(4/side)//","// &
         format_real(1/(4*d)))
      call add_line(b(5), "structure,"//fitted(dsf, nsf)//","//fitted(dsf + 1, nsf)//","//format_real(d)//","// &
         format_real(side/16))
      allocate(texts(11))
      do k = 1, 5
         texts(k)%s = built_text(b(k))
      end do
      ! Plain arrays (a component of an array of derived type would be copied per call).
      box = stats%box
      texts(6)%s = summit_plot("summit density against box size (thesis Fig. 3.2a)", "summits per um^2", &
         box, [(stats(k)%density, k = 1, size(stats))], e(1), p(1))
      texts(7)%s = summit_plot("mean summit height against box size (thesis Fig. 3.2b)", "mean height (nm)", &
         box, [(stats(k)%mean_height, k = 1, size(stats))], e(2), p(2))
      texts(8)%s = summit_plot("mean radius of curvature against box size (thesis Fig. 3.2c)", "mean radius (nm)", &
         box, [(stats(k)%mean_radius, k = 1, size(stats))], e(3), p(3))
      if (allocated(series)) deallocate(series)
      allocate(series(0))
      call add_series(series, "profile PSD", freq, power, markers=.false.)
      texts(9)%s = svg_multi_plot("power spectral density: D = "//said(dpsd, npsd)//" (eq. 3.1, slope "// &
         said(slope, npsd)//")", "frequency (1/nm)", "power (nm^3)", series, .true., .true.)
      if (allocated(series)) deallocate(series)
      allocate(series(0))
      call add_series(series, "structure function", tau, sf, markers=.false.)
      texts(10)%s = svg_multi_plot("structure function: D = "//said(dsf, nsf)//" (eq. 2.15)", "tau (nm)", &
         "S (nm^2)", series, .true., .true.)
      texts(11)%s = study_json("summits", args, opts%input, opts%prefix, names, texts(1:10))
      call write_file_set(names, texts, status)
      if (status%code /= 0) then
         call fail_with("summits", status, code)
         return
      end if
      if (.not. opts%quiet) then
         write(output_unit, '(a)') "femcod summits: "//int_str(size(z, 1))//" x "//int_str(size(z, 2))//" heights, pixel "// &
            sig_str(d, 6)//" nm, "//int_str(size(stats))//" box sizes from "//sig_str(stats(1)%box, 4)//" to "// &
            sig_str(stats(size(stats))%box, 4)//" nm"
         write(output_unit, '(a)') "  density ~ d^"//sig_str(e(1), 4)//", height ~ d^"//sig_str(e(2), 4)// &
            ", radius ~ d^"//sig_str(e(3), 4)
         write(output_unit, '(a)') "  fractal dimension of a profile: "//said(dpsd, npsd)//" (PSD), "//said(dsf, nsf)// &
            " (structure function); surface: +1"
         write(output_unit, '(a)') "  wrote "//opts%prefix//".summits.csv, .summit_exponents.csv, .psd.csv, .structure.csv, "// &
            ".fractal.csv, .summits.json (the tables) and 5 SVG figures"
      end if
   contains
      !> A fitted value for the CSV ("" when its range held fewer than two points).
      function fitted(value, points) result(text)
         real(dp), intent(in) :: value
         integer, intent(in) :: points
         character(len=:), allocatable :: text
         text = ""
         if (points >= 2) text = format_real(value)
      end function fitted
      !> A fitted value for the summary and figures ("not determined" likewise).
      function said(value, points) result(text)
         real(dp), intent(in) :: value
         integer, intent(in) :: points
         character(len=:), allocatable :: text
         text = "not determined"
         if (points >= 2) text = sig_str(value, 4)
      end function said
   end subroutine summits_command
end module femcod_summits_command
