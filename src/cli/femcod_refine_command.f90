!> `femcod refine DECK --loads F1,...`: the thesis' third model (section 5.3,
!> studies/femcod_refine): the real area fraction against magnification, from the pixel
!> down to --down-to, by the refinement below the pixel, beside Richardson's
!> extrapolation (section 4.5) and Persson's theory on the same PSD.
module femcod_refine_command
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_strings, only: string_type, int_str, sig_str, format_real, text_builder, add_line, built_text, &
      json_string, json_number
   use femcod_about, only: FEMCOD_VERSION
   use femcod_memory, only: available_memory
   use femcod_problem, only: contact_problem
   use femcod_heights, only: is_height_file
   use femcod_solver_options, only: contact_options, validate_options, SOLVER_CG, boundary_from_name, &
      BOUNDARY_PERIODIC
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, flag_option, real_option, &
      text_option, choice_option, real_list_option, get_option, option_given, scene_options, refuse_options
   use femcod_help, only: help_requested, print_lines
   use femcod_results, only: write_file_set
   use femcod_svg, only: svg_series, add_series, svg_multi_plot
   use femcod_files, only: default_prefix
   use femcod_studies, only: check_outputs, surface_scene, study_deck, command_text
   use femcod_generate, only: scene_spec
   use femcod_refine_study, only: refine_answer, refine_contact
   implicit none
   private
   public :: refine_command, refine_table

   !> The default cut-off (nm): about the spacing of atoms, below which a continuum's
   !> spectrum has no meaning.
   real(dp), parameter :: ATOMIC_CUTOFF = 0.25_dp

contains

   function refine_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [ &
         real_list_option("--loads", "F1,...", "total loads in nN (required)", lower=0.0_dp, closed="()"), &
         real_option("--down-to", "LENGTH", "refine down to this length in nm (default 0.25, about the spacing "// &
            "of atoms; it must be below the pixel)", lower=0.0_dp, closed="()"), &
         choice_option("--boundary", "free|periodic", "the solve's boundary (default free; periodic for a cell)"), &
         real_option("--tol", "T", "the cg solver's tolerance (default 1e-8)", lower=0.0_dp, closed="()"), &
         text_option("--output", "PREFIX", "output prefix (default: the deck's name)", alias="-o"), &
         flag_option("--force", "replace the outputs of an earlier refine"), &
         flag_option("--quiet", "no summary", alias="-q"), &
         scene_options("heights")]
   end function refine_table

   subroutine refine_help()
      write(output_unit, '(a)') &
         "usage: femcod refine DECK --loads F1,... [--down-to LENGTH] [--boundary free|periodic] [-o PREFIX]", &
         "       femcod refine FILE --loads F1,... [--pixel D] [--young E] [--poisson NU] [--remove-plane] ...", &
         "         (a height file: an ASCII matrix, HDF5, Gwyddion or NanoScope, with the units and pixel it", &
         "         gives, on an elastic body against a rigid flat, as femcod run --lower)", &
         "", &
         "The thesis' third model (section 5.3): the deck solved at its resolution (cg), the surface's PSD", &
         "fitted by a power law over 4 q_L .. q_d/2, and each contact pixel refined below the pixel by", &
         "Persson's erf of its own mean pressure over the roughness the power law continues, with a", &
         "constant (kappa) measured on the image over the octaves 2d to d, 4d to 2d and 4d to d, and for", &
         "the band below the pixel its law in the band's octaves and scale (doc/studies.md).", &
         "Beside it: Richardson's extrapolation from solves at 2d and 4d (section 4.5) and Persson's theory", &
         "of the whole surface. A surface whose PSD is not a power law (no scaling range) is refused.", ""
      call print_lines(option_help(refine_table(), "heights"))
      write(output_unit, '(a)') "", &
         "outputs: PREFIX.refine.csv  load_nN,magnification,pixel_nm,area_fraction_solve,area_fraction_refined,", &
         "                            area_fraction_richardson,area_fraction_persson,", &
         "                            area_fraction_refined_sqrt2 (Persson's constant in place of kappa),", &
         "                            kappa (the constant of that magnification's band)", &
         "         PREFIX.refine.svg  area fraction against magnification, one curve per method and load"
   end subroutine refine_help

   subroutine refine_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(parsed_options) :: parsed
      type(status_type) :: status
      type(contact_problem) :: problem
      type(contact_options) :: options
      type(refine_answer) :: answer
      type(scene_spec) :: spec
      type(string_type), allocatable :: names(:), texts(:)
      character(len=:), allocatable :: prefix, deck, boundary
      real(dp) :: down_to
      logical :: force, quiet
      code = 0
      if (help_requested(args)) then
         call refine_help()
         return
      end if
      call parse_options(refine_table(), args, parsed, status)
      if (status%code == 0 .and. size(parsed%positional) /= 1) call set_error(status, STATUS_USAGE, &
         "refine needs one DECK or height file")
      if (status%code == 0) call refuse_options(parsed, merge("heights", "       ", option_given(parsed, "--pixel") .or. &
         is_height_file(parsed%positional(1)%s)), "heights=to a height file (FILE [--pixel D]), not to a deck", status)
      if (status%code == 0 .and. .not. option_given(parsed, "--loads")) call set_error(status, STATUS_USAGE, &
         "refine needs --loads F1,... (nN)")
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod refine: "//status%message//" (femcod refine --help)"
         code = status%code
         return
      end if
      deck = parsed%positional(1)%s
      prefix = default_prefix(deck)
      down_to = ATOMIC_CUTOFF
      force = .false.
      quiet = .false.
      boundary = "free"
      call get_option(parsed, "--output", prefix)
      call get_option(parsed, "--down-to", down_to)
      call get_option(parsed, "--force", force)
      call get_option(parsed, "--quiet", quiet)
      call get_option(parsed, "--boundary", boundary)
      options%solver = SOLVER_CG
      options%boundary = boundary_from_name(boundary)
      allocate(options%approaches(0))
      call get_option(parsed, "--loads", options%loads)
      call get_option(parsed, "--tol", options%cg%tol)
      call validate_options(options, status)
      names = [string_type(prefix//".refine.csv"), string_type(prefix//".refine.svg"), &
         string_type(prefix//".refine.json")]
      if (status%code == 0) call check_outputs(names, deck, force, status)
      ! A deck, or a height file on an elastic body against a rigid flat (the studies' scene).
      call surface_scene(parsed, deck, spec)
      if (status%code == 0) call study_deck(deck, spec, problem, status)
      options%memory_available = available_memory()
      if (status%code == 0) call refine_contact(problem, options, down_to, answer, status)
      if (status%code == 0) then
         allocate(texts(3))
         texts(1)%s = refine_csv(answer, problem%pixel)
         texts(2)%s = refine_svg(answer, problem)
         texts(3)%s = refine_json(deck, args, problem, boundary, down_to, answer)
         call write_file_set(names, texts, status)
      end if
      if (status%code /= 0) then
         write(error_unit, '(a)') "femcod refine: "//status%message
         code = status%code
         return
      end if
      if (.not. quiet) call print_refine(deck, prefix, problem, options, down_to, answer)
   end subroutine refine_command

   function refine_csv(answer, pixel) result(text)
      type(refine_answer), intent(in) :: answer
      real(dp), intent(in) :: pixel
      character(len=:), allocatable :: text
      type(text_builder) :: b
      integer :: k, z
      call add_line(b, "load_nN,magnification,pixel_nm,area_fraction_solve,area_fraction_refined,"// &
         "area_fraction_richardson,area_fraction_persson,area_fraction_refined_sqrt2,kappa,area_load_slope_solve,"// &
         "area_load_slope_refined,area_fraction_band_low,area_fraction_band_high,kappa_band_low,kappa_band_high")
      do k = 1, size(answer%loads)
         do z = 1, size(answer%zeta)
            call add_line(b, format_real(answer%loads(k))//","//format_real(answer%zeta(z))//","// &
               format_real(pixel/answer%zeta(z))//","//format_real(answer%coarse(1, k))//","// &
               format_real(answer%refined(z, k))//","//format_real(answer%richardson(z, k))//","// &
               format_real(answer%persson(z, k))//","//format_real(answer%theory(z, k))//","// &
               format_real(answer%band(z))//","//format_real(answer%slope_solve(k))//","// &
               format_real(answer%slope_refined(z, k))//","//format_real(answer%refined_low(z, k))//","// &
               format_real(answer%refined_high(z, k))//","//format_real(answer%band_low(z))//","// &
               format_real(answer%band_high(z)))
         end do
      end do
      text = built_text(b)
   end function refine_csv

   !> PREFIX.refine.json (beside a run's PREFIX.summary.json of the same deck, not over it):
   !> what refine prints and writes, as numbers whose names carry
   !> their units: the scene, the spectrum's fit, and per load the solve's area fraction
   !> and area-load slope with every magnification's refined area fraction and its band,
   !> the Richardson and Persson area fractions and the refined slope.
   function refine_json(deck, args, problem, boundary, down_to, answer) result(j)
      character(len=*), intent(in) :: deck, boundary
      type(string_type), intent(in) :: args(:)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: down_to
      type(refine_answer), intent(in) :: answer
      character(len=:), allocatable :: j, line
      character(len=1), parameter :: nl = new_line("a")
      integer :: k, z
      line = command_text("refine", args)
      associate(s => answer%spectrum)
         j = '{'//nl//'  "femcod_version": '//json_string(FEMCOD_VERSION)//','//nl// &
            '  "command": "refine", "command_line": '//json_string(line)//','//nl// &
            '  "deck": '//json_string(deck)//','//nl// &
            '  "scene": {"label": '//json_string(problem%label)//', "NP": '//int_str(problem%np)//', "pixel_nm": '// &
            json_number(problem%pixel)//', "composite_modulus_GPa": '//json_number(answer%estar)//'},'//nl// &
            '  "boundary": '//json_string(boundary)//', "down_to_nm": '//json_number(down_to)//','//nl// &
            '  "spectrum": {"prefactor_nm4": '//json_number(s%prefactor)//', "hurst": '//json_number(s%hurst)// &
            ', "fit_from_per_nm": '//json_number(s%q_low)//', "fit_to_per_nm": '//json_number(s%q_high)// &
            ', "bins": '//int_str(s%points)//', "r_squared": '//json_number(s%r_squared)// &
            ', "rms_slope": '//json_number(sqrt(s%slope_variance))//'},'//nl// &
            '  "rms_slope": '//json_number(answer%rms_slope)//','//nl//'  "loads": ['//nl
      end associate
      do k = 1, size(answer%loads)
         j = j//'    {"load_nN": '//json_number(answer%loads(k))//', "area_fraction_solve": '// &
            json_number(answer%coarse(1, k))//', "area_load_slope_solve": '//json_number(answer%slope_solve(k))// &
            ', "kappa_one_octave": '//json_number(answer%kappa(k))//', "kappa_coarser_octave": '// &
            json_number(answer%kappa_coarse)//', "kappa_two_octaves": '//json_number(answer%kappa_two)// &
            ', "kappa_decay": '//json_number(answer%decay)//', "kappa_drift": '//json_number(answer%drift)// &
            ', "magnifications": ['
         do z = 1, size(answer%zeta)
            j = j//nl//'      {"magnification": '//json_number(answer%zeta(z))//', "pixel_nm": '// &
               json_number(problem%pixel/answer%zeta(z))//', "kappa": '//json_number(answer%band(z))// &
               ', "area_fraction_refined": '// &
               json_number(answer%refined(z, k))//', "area_fraction_richardson": '// &
               json_number(answer%richardson(z, k))//', "area_fraction_persson": '//json_number(answer%persson(z, k))// &
               ', "area_fraction_refined_sqrt2": '//json_number(answer%theory(z, k))//', "area_load_slope_refined": '// &
               json_number(answer%slope_refined(z, k))//', "kappa_band": ['//json_number(answer%band_low(z))// &
               ', '//json_number(answer%band_high(z))//'], "area_fraction_band": ['// &
               json_number(answer%refined_low(z, k))//', '//json_number(answer%refined_high(z, k))//']}'// &
               trim(merge(",", " ", z < size(answer%zeta)))
         end do
         j = j//']}'//trim(merge(",", " ", k < size(answer%loads)))//nl
      end do
      j = j//'  ],'//nl//'  "timings_s": {"solve": '//json_number(answer%solve_seconds)//', "richardson_solves": '// &
         json_number(answer%richardson_seconds)//', "spectrum_and_refinement": '// &
         json_number(answer%refine_seconds)//'}'//nl//'}'//nl
   end function refine_json

   function refine_svg(answer, problem) result(svg)
      type(refine_answer), intent(in) :: answer
      type(contact_problem), intent(in) :: problem
      character(len=:), allocatable :: svg
      type(svg_series), allocatable :: series(:)
      integer :: k
      allocate(series(0))
      do k = 1, size(answer%loads)
         call add_series(series, "refined, "//sig_str(answer%loads(k), 4)//" nN", answer%zeta, answer%refined(:, k))
         if (all(answer%richardson(:, k) == answer%richardson(:, k))) call add_series(series, "Richardson, "// &
            sig_str(answer%loads(k), 4)//" nN", answer%zeta, answer%richardson(:, k), dashed=.true., markers=.false.)
         call add_series(series, "Persson, "//sig_str(answer%loads(k), 4)//" nN", answer%zeta, answer%persson(:, k), &
            dashed=.true., markers=.false.)
      end do
      svg = svg_multi_plot("femcod refine: "//problem%label, "magnification (pixel "//format_real(problem%pixel)// &
         " nm / length)", "real area fraction", series, .true., .true.)
   end function refine_svg

   subroutine print_refine(deck, prefix, problem, options, down_to, answer)
      character(len=*), intent(in) :: deck, prefix
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      real(dp), intent(in) :: down_to
      type(refine_answer), intent(in) :: answer
      integer :: k, last
      character(len=:), allocatable :: bnd
      last = size(answer%zeta)
      bnd = "free"
      if (options%boundary == BOUNDARY_PERIODIC) bnd = "periodic"
      write(output_unit, '(a)') "femcod refine "//deck//" (cg, "//bnd//"): NP = "//int_str(problem%np)//", d = "// &
         format_real(problem%pixel)//" nm, E* = "//sig_str(answer%estar, 5)//" GPa"
      associate(s => answer%spectrum)
         write(output_unit, '(a)') "  spectrum  : C(q) = "//sig_str(s%prefactor, 4)//" q^-(2+2H), H = "// &
            sig_str(s%hurst, 3)//", fitted from "//sig_str(s%q_low, 3)//" to "//sig_str(s%q_high, 3)// &
            " 1/nm ("//int_str(s%points)//" bins, r^2 "//sig_str(s%r_squared, 4)//"); rms slope of the image "// &
            sig_str(sqrt(s%slope_variance), 4)
      end associate
      write(output_unit, '(a)') "  down to   : "//format_real(down_to)//" nm, magnification "// &
         sig_str(answer%zeta(last), 4)
      write(output_unit, '(a)') "  kappa     : "//sig_str(answer%kappa(1), 4)//" over the octave 2d to d, "// &
         sig_str(answer%kappa_coarse, 4)//" over 4d to 2d, "//sig_str(answer%kappa_two, 4)//" over 4d to d: "// &
         "N^-"//sig_str(answer%decay, 3)//" in a band's octaves N, x "//sig_str(answer%drift, 3)// &
         " an octave finer; "//sig_str(answer%band(last), 4)//" over the "// &
         sig_str(log(answer%zeta(last))/log(2.0_dp), 3)//" octaves refined (band "// &
         sig_str(answer%band_low(last), 4)//" to "//sig_str(answer%band_high(last), 4)//")"
      do k = 1, size(answer%loads)
         write(output_unit, '(a)') "  at load   : "//sig_str(answer%loads(k), 6)//" nN: the solve "// &
            sig_str(100*answer%coarse(1, k), 4)//" %; refined "//sig_str(100*answer%refined(last, k), 4)// &
            " % (band "//sig_str(100*answer%refined_low(last, k), 3)//" to "// &
            sig_str(100*answer%refined_high(last, k), 3)//" %), Richardson "// &
            sig_str(100*answer%richardson(last, k), 4)//" %, Persson "// &
            sig_str(100*answer%persson(last, k), 4)//" % at "//format_real(down_to)//" nm (kappa "// &
            sig_str(answer%band(last), 4)//", Persson's sqrt(2) gives "//sig_str(100*answer%theory(last, k), 4)//" %)"
         write(output_unit, '(a)') "              area-load slope (A/A0)/(p/(E* h'_rms)): the solve "// &
            sig_str(answer%slope_solve(k), 4)//" (h'_rms "//sig_str(answer%rms_slope, 4)//" at the pixel), refined "// &
            sig_str(answer%slope_refined(last, k), 4)//" (with the slope down to "//format_real(down_to)//" nm)"
      end do
      write(output_unit, '(a)') "  cost      : the solve "//sig_str(answer%solve_seconds, 3)//" s; spectrum, fit "// &
         "and refinement "//sig_str(answer%refine_seconds, 3)//" s; the solves at 2d and 4d (Richardson) "// &
         sig_str(answer%richardson_seconds, 3)//" s"
      write(output_unit, '(a)') "  written   : "//prefix//".refine.csv, .refine.svg, .refine.json"
   end subroutine print_refine
end module femcod_refine_command
