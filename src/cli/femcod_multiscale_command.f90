!> `femcod multiscale`: the hierarchical multiscale Hertz model of the thesis' section 3.3
!> (studies/femcod_multiscale), its table and figure.
module femcod_multiscale_command
   use, intrinsic :: iso_fortran_env, only: output_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_strings, only: string_type, int_str, sig_str, text_builder, add_line, built_text, format_real
   use femcod_heights, only: is_height_file
   use femcod_results, only: write_file_set
   use femcod_svg, only: svg_series, svg_multi_plot, add_series
   use femcod_summits, only: summit_statistics, summit_search, summits_of_size, default_sizes, summit_power_laws
   use femcod_multiscale, only: roughness_template, multiscale_result, multiscale_hertz, check_growth
   use femcod_help, only: print_lines
   use femcod_options, only: parsed_options, option_help, get_option, option_given
   use femcod_studies, only: surface_options, check_outputs, study_json, study_heights, surface_table, parse_surface_options, &
      fail_with
   implicit none
   private
   public :: multiscale_command

contains

   subroutine multiscale_help()
      write(output_unit, '(a)') &
         "usage: femcod multiscale FILE [--pixel D] [--sizes ...] [--template-size n] [--s 2.5,5,10]", &
         "                         [--min-length 4] [--scales K] [--load 1e6] [--estar 200] [--exponents eh,eR,eN]", &
         "                         [--remove-plane] [-o PREFIX] [--force] [--quiet]", &
         "", &
         "The hierarchical multiscale Hertz model of the thesis, section 3.3. The summit search of", &
         "`femcod summits` gives the power laws of summit height, radius and density against the box size", &
         "and the roughness template (the summits of one size); the template is scaled to the finer length", &
         "scales d1/s^(k-1), and the load is shared down the scales by Hertz contacts (eqs. 3.9-3.13), with", &
         "the close-packed and the asperity-density constraints on the asperities a host carries (3.3.1).", ""
      call print_lines(option_help(surface_table("multiscale"), ""))
      write(output_unit, '(a)') "", &
         "outputs: PREFIX.multiscale.csv  s,constraint,scale,length_nm,load_nN,area_nm2,contacts", &
         "         PREFIX.multiscale.svg (area against the smallest length scale, Fig. 3.10)", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O"
   end subroutine multiscale_help

   !> `femcod multiscale`.
   subroutine multiscale_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(surface_options) :: opts
      type(string_type), allocatable :: names(:), texts(:)
      type(parsed_options) :: parsed
      type(status_type) :: status
      type(summit_statistics), allocatable :: stats(:)
      type(roughness_template) :: template
      type(multiscale_result) :: result
      type(text_builder) :: b
      type(svg_series), allocatable :: series(:)
      real(dp), allocatable :: z(:, :), svals(:), heights(:), rx(:), ry(:), ex(:)
      integer, allocatable :: rows(:), cols(:)
      character(len=12), parameter :: constraints(2) = [character(len=12) :: "close-packed", "density"]
      real(dp) :: d, load, estar, deck_estar, min_length, region, e3(3), p3(3)
      integer :: k, scales, tsize, ks, kc, m, best
      logical :: ok
      call parse_surface_options("multiscale", args, opts, parsed, code)
      if (code == -1) then
         code = 0
         call multiscale_help()
         return
      end if
      if (code /= 0) return
      svals = [2.5_dp, 5.0_dp, 10.0_dp]
      load = 1.0e6_dp
      estar = 200
      min_length = 4
      scales = 0
      tsize = 0
      allocate(ex(0))
      call get_option(parsed, "--s", svals)
      call get_option(parsed, "--exponents", ex)
      call get_option(parsed, "--load", load)
      call get_option(parsed, "--estar", estar)
      call get_option(parsed, "--min-length", min_length)
      call get_option(parsed, "--scales", scales)
      call get_option(parsed, "--template-size", tsize)
      names = [string_type(opts%prefix//".multiscale.csv"), string_type(opts%prefix//".multiscale.svg"), &
         string_type(opts%prefix//".multiscale.json")]
      ! A deck gives its materials: E* is the deck's, and --estar next to it would be a
      ! second answer to one question.
      if (option_given(parsed, "--estar") .and. .not. (opts%pixel > 0 .or. is_height_file(opts%input))) then
         call set_error(status, STATUS_USAGE, "--estar: "//opts%input//" is a deck and gives its own materials "// &
            "(E* from E1, nu1, E2, nu2); give --estar only with a height file")
         call fail_with("multiscale", status, code)
         return
      end if
      ! The outputs are checked before the input is read: an input is never an output.
      call check_outputs(names, opts%input, opts%force, status)
      if (status%code == 0) call study_heights(opts%input, opts%pixel, opts%plane, z, d, status, opts%height_unit, &
         deck_estar)
      if (deck_estar > 0) estar = deck_estar
      if (status%code /= 0) then
         call fail_with("multiscale", status, code)
         return
      end if
      if (size(opts%sizes) == 0) opts%sizes = default_sizes(size(z, 1))
      if (tsize > 0 .and. .not. any(opts%sizes == tsize)) opts%sizes = [opts%sizes, tsize]
      if (status%code == 0) call summit_search(z, d, opts%sizes, stats, status)
      if (status%code /= 0) then
         call fail_with("multiscale", status, code)
         return
      end if
      if (size(ex) == 0) then
         call summit_power_laws(stats, e3, p3)
         ! The model takes heights, radii, density in that order.
         ex = [e3(2), e3(3), e3(1)]
      end if
      if (tsize == 0) then
         best = minloc(abs(stats%count - 100), 1)
         tsize = stats(best)%n
      end if
      ! The template: the summits of that size whose paraboloid opens downwards.
      call summits_of_size(z, d, tsize, maxval(opts%sizes), rows, cols, heights, rx, ry)
      template%heights = pack(heights, rx > 0 .and. ry > 0)
      template%radii = pack(sqrt(rx*ry), rx > 0 .and. ry > 0)
      template%box = (2*tsize + 1)*d
      region = real(size(z, 1) - 2*maxval(opts%sizes), dp)*(size(z, 2) - 2*maxval(opts%sizes))*d**2
      template%density = size(heights)/region
      ! Every (s, constraint) is estimated from its first two scales before the first is
      ! run whole: what would pass the model's limit is refused at once (exit 4).
      do ks = 1, size(svals)
         m = scales
         if (m == 0) m = max(1, 1 + floor(log(template%box/min_length)/log(svals(ks))))
         do kc = 1, 2
            if (m < 3) cycle
            call multiscale_hertz(template, ex(1), ex(2), ex(3), svals(ks), 2, load, estar, trim(constraints(kc)), &
               result, status)
            call check_growth(result%contacts(1), result%contacts(2), 2, m, status)
            if (status%code /= 0) then
               status%message = "s = "//sig_str(svals(ks), 3)//", "//trim(constraints(kc))//": "//status%message
               call fail_with("multiscale", status, code)
               return
            end if
         end do
      end do
      call add_line(b, "s,constraint,scale,length_nm,load_nN,area_nm2,contacts")
      allocate(series(0))
      do ks = 1, size(svals)
         m = scales
         if (m == 0) m = max(1, 1 + floor(log(template%box/min_length)/log(svals(ks))))
         do kc = 1, 2
            call multiscale_hertz(template, ex(1), ex(2), ex(3), svals(ks), m, load, estar, trim(constraints(kc)), &
               result, status)
            if (status%code /= 0) then
               call fail_with("multiscale", status, code)
               return
            end if
            do k = 1, m
               call add_line(b, format_real(svals(ks))//","//trim(constraints(kc))//","//int_str(k)//","// &
                  format_real(result%length(k))//","//format_real(load)//","//format_real(result%area(k))//","// &
                  int_str(result%contacts(k)))
            end do
            call add_series(series, "s = "//sig_str(svals(ks), 3)//", "//trim(constraints(kc)), result%length, &
               result%area, dashed=kc == 2)
         end do
      end do
      allocate(texts(3))
      texts(1)%s = built_text(b)
      texts(2)%s = svg_multi_plot("true contact area against the smallest length scale (thesis Fig. 3.10)", &
         "smallest length scale (nm)", "true contact area (nm^2)", series, .true., .true.)
      texts(3)%s = study_json("multiscale", args, opts%input, opts%prefix, names, texts(1:2))
      call write_file_set(names, texts, status)
      if (status%code /= 0) then
         call fail_with("multiscale", status, code)
         return
      end if
      if (.not. opts%quiet) then
         write(output_unit, '(a)') "femcod multiscale: template of "//int_str(size(template%heights))//" summits (n = "// &
            int_str(tsize)//", box "//sig_str(template%box, 4)//" nm, density "//sig_str(template%density*1.0e6_dp, 4)// &
            " per um^2); heights ~ d^"//sig_str(ex(1), 3)//", radii ~ d^"//sig_str(ex(2), 3)//", density ~ d^"// &
            sig_str(ex(3), 3)//"; E* = "//sig_str(estar, 4)//" GPa ("// &
            trim(merge("the deck's materials  ", "--estar or its default", deck_estar > 0))//")"
         write(output_unit, '(a)') "  wrote "//opts%prefix//".multiscale.csv and .multiscale.svg"
      end if
   end subroutine multiscale_command
end module femcod_multiscale_command
