!> The command-line studies of the thesis: `femcod resolution` (section 4.5), `femcod
!> summits` (chapter 3: summit search, PSD, structure function) and `femcod multiscale`
!> (section 3.3). Each reads its input, calls the numerical modules, and writes its CSV
!> and SVG files as one set (temporaries renamed into place; nothing on failure).
module femcod_studies
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_BAD_INPUT, STATUS_IO, STATUS_NUMERICAL
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_shear_model, only: friction_coefficient
   use femcod_strings, only: string_type, int_str, sig_str, split_list, text_builder, add_line, built_text, &
      parse_real, parse_integer, format_real, parse_real_list, parse_integer_list
   use femcod_generate, only: scene_spec
   use femcod_heights, only: load_scene, read_height_map, height_map, is_height_file, height_file_path, &
      looks_like_height_matrix
   use femcod_files, only: default_prefix, file_part
   use femcod_output_guard, only: guard_outputs, OUTPUT_RESULT
   use femcod_results, only: write_file_set
   use femcod_svg, only: svg_series, svg_multi_plot, add_series
   use femcod_clock, only: wall_clock
   use femcod_resolution_study, only: resolution_level, solve_level, extrapolate_levels, check_levels
   use femcod_summits, only: summit_statistics, summit_search, summits_of_size, default_sizes, profile_psd, summit_power_laws, &
      structure_function, psd_dimension, structure_dimension, summits_storage_bytes
   use femcod_memory, only: available_memory, memory_text, usable_text
   use femcod_multiscale, only: roughness_template, multiscale_result, multiscale_hertz, check_growth
   use femcod_scene, only: flip_upper
   use femcod_surfaces, only: remove_plane
   use femcod_richardson, only: power_law_fit
   use femcod_observer, only: solver_observer
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, scene_options, flag_option, &
      real_option, integer_option, text_option, choice_option, real_list_option, integer_list_option, get_option, &
      option_given, refuse_options
   implicit none
   private
   public :: resolution_command, summits_command, multiscale_command, resolution_table, surface_table, check_outputs

   !> Options shared by `summits` and `multiscale`.
   type :: surface_options
      character(len=:), allocatable :: input, prefix, height_unit
      real(dp) :: pixel = 0
      logical :: plane = .false., force = .false., quiet = .false.
      integer, allocatable :: sizes(:)
   end type surface_options

   !> Progress of the solve inside a level: a line on standard error every 10 s.
   type, extends(solver_observer) :: level_observer
      logical :: quiet = .false.
      real(dp) :: last_report = 0
   contains
      procedure :: progress => level_progress
   end type level_observer

contains

   !> The options of `femcod resolution`; "heights" ones apply to a height file only.
   function resolution_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [ &
         text_option("--output", "PREFIX", "output prefix (default: the input's name)", alias="-o"), &
         integer_list_option("--levels", "L1,...", "NP of each level (default: NP, NP/2, NP/4, NP/8 down to 8 "// &
            "pixels)", lower=1), &
         choice_option("--method", "subsample|average", "odd/odd pixels (default) or 2 x 2 means"), &
         real_option("--hardness", "H", "GPa, for the pixels above the hardness per step (default 11, polysilicon)", &
            lower=0.0_dp, closed="()"), &
         real_option("--shear-strength", "TAU0", "friction from the pressures as in femcod run: tau = TAU0 + "// &
            "ALPHA p (GPa) on each contact pixel; adds friction_nN and friction_coefficient to PREFIX.resolution.csv "// &
            "and the coefficient at a common load to the summary", lower=0.0_dp), &
         real_option("--shear-slope", "ALPHA", "the shear strength's pressure coefficient (1, default 0)", &
            lower=0.0_dp), &
         flag_option("--force", "replace existing result files"), &
         flag_option("--quiet", "no summary, no progress lines", alias="-q"), &
         scene_options("heights")]
   end function resolution_table

   subroutine resolution_help()
      write(output_unit, '(a)') &
         "usage: femcod resolution DECK [--levels 512,256,128,64] [--method subsample|average] [-o PREFIX]", &
         "                         [--hardness H] [--shear-strength TAU0] [--shear-slope ALPHA] [--force] [--quiet]", &
         "       femcod resolution FILE --pixel D [--young E] [--poisson NU] [--maxcont M] [--remove-plane]", &
         "                         [options as above]", &
         "", &
         "The resolution study of the thesis, section 4.5: the surfaces down-sampled by keeping the odd/odd", &
         "pixels (subsample, default) or by averaging 2 x 2 blocks (average), the pixel size doubling at each", &
         "halving and MAXCONT scaled with the pixel count; the event-exact contact history at every level,", &
         "and beside it the estimates of Figs. 4.17, 4.18 and 4.21. FILE: heights (nm) as an ASCII matrix or", &
         "FILE.h5:/dataset on an elastic lower body (default 200 GPa, 0.25) against a rigid flat.", ""
      call print_lines(option_help(resolution_table(), ""))
      write(output_unit, '(a)') "with a height file (FILE --pixel D):"
      call print_lines(option_help(resolution_table(), "heights"))
      write(output_unit, '(a)') "", &
         "outputs: PREFIX.resolution.csv  np,method,load_nN,approach_nm,area_nm2 (one row per step and level;", &
         "                                with the shear model also friction_nN,friction_coefficient)", &
         "         PREFIX.powerlaw.csv    np,exponent,prefactor (area = prefactor * load^exponent over the run)", &
         "         PREFIX.estimates.csv   np,model,load_nN,area_nm2 with model coupled (femcod), uncoupled", &
         "                                (rigid substrate, independent voxels of the single-pixel compliance,", &
         "                                at femcod's approaches), mccool (Greenwood-Williamson from the RMS", &
         "                                height, slope and curvature at that resolution, at femcod's loads),", &
         "                                richardson (rate-1 extrapolation from the next coarser level; np is", &
         "                                the finer one)", &
         "         PREFIX.hardness.csv    np,step,area_fraction,contacts,n_above_hardness,fraction_above_hardness", &
         "         PREFIX.hardness_capped.csv  np,step,load_nN,area_fraction,contacts,n_plastic,fraction_plastic:", &
         "                                the finest level again with pressures capped at H (--plastic)", &
         "         PREFIX.load_displacement.svg, .area_displacement.svg (Fig. 4.17), .area_pressure.svg,", &
         "         .richardson.svg (Fig. 4.18), .hardness.svg (Fig. 4.21)", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O"
   end subroutine resolution_help



   !> `femcod resolution`.
   subroutine resolution_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(contact_problem) :: deck
      type(status_type) :: status
      type(resolution_level), allocatable :: levels(:)
      type(string_type), allocatable :: names(:), texts(:)
      type(parsed_options) :: parsed
      type(scene_spec) :: spec
      type(level_observer) :: observer
      integer, allocatable :: nps(:)
      character(len=:), allocatable :: input, prefix, method
      real(dp) :: hardness, t0, t1, shear(2)
      integer :: k, n
      logical :: force, quiet, friction
      code = 0
      if (help_requested(args)) then
         call resolution_help()
         return
      end if
      call parse_options(resolution_table(), args, parsed, status)
      if (status%code == 0) then
         if (size(parsed%positional) == 0) call set_error(status, STATUS_USAGE, "no deck or height file given")
         if (size(parsed%positional) > 1) call set_error(status, STATUS_USAGE, "one input only (found '"// &
            parsed%positional(1)%s//"' and '"//parsed%positional(2)%s//"')")
      end if
      if (status%code == 0) call refuse_options(parsed, merge("heights", "       ", option_given(parsed, "--pixel") .or. &
         is_height_file(parsed%positional(1)%s)), &
         "heights=to a height file (FILE --pixel D), not to a deck", status)
      if (status%code /= 0) then
         call usage(status%message)
         return
      end if
      input = parsed%positional(1)%s
      prefix = ""
      method = "subsample"
      hardness = 11
      force = .false.
      quiet = .false.
      allocate(nps(0))
      call get_option(parsed, "--output", prefix)
      call get_option(parsed, "--method", method)
      call get_option(parsed, "--levels", nps)
      call get_option(parsed, "--hardness", hardness)
      friction = option_given(parsed, "--shear-strength") .or. option_given(parsed, "--shear-slope")
      shear = 0
      call get_option(parsed, "--shear-strength", shear(1))
      call get_option(parsed, "--shear-slope", shear(2))
      call get_option(parsed, "--force", force)
      call get_option(parsed, "--quiet", quiet)
      if (prefix == "") prefix = default_prefix(file_part(input))
      names = [string_type(prefix//".resolution.csv"), string_type(prefix//".powerlaw.csv"), &
         string_type(prefix//".estimates.csv"), string_type(prefix//".hardness.csv"), &
         string_type(prefix//".load_displacement.svg"), string_type(prefix//".area_displacement.svg"), &
         string_type(prefix//".area_pressure.svg"), string_type(prefix//".richardson.svg"), &
         string_type(prefix//".hardness.svg"), string_type(prefix//".hardness_capped.csv")]
      ! The outputs are checked before the input is read: an input is never an output.
      call check_outputs(names, input, force, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      call surface_scene(parsed, input, spec)
      call study_deck(input, spec, deck, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      if (size(nps) == 0) then
         n = deck%np
         do while (n >= 8 .and. size(nps) < 4)
            nps = [nps, n]
            if (method == "average") then
               n = n/2
            else
               n = (n + 1)/2
            end if
         end do
         if (size(nps) == 0) nps = [deck%np]
      end if
      call check_levels(deck%np, nps, method, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      observer%quiet = quiet
      allocate(levels(size(nps)))
      do k = 1, size(nps)
         call wall_clock(t0)
         observer%last_report = 0
         ! The finest level also with the pressures capped at H (Fig. 4.21's capped curve).
         if (friction) then
            call solve_level(deck, nps(k), method, hardness, levels(k), status, observer, &
               capped=nps(k) == maxval(nps), shear=shear)
         else
            call solve_level(deck, nps(k), method, hardness, levels(k), status, observer, &
               capped=nps(k) == maxval(nps))
         end if
         if (status%code /= 0) then
            status%message = "level NP = "//int_str(nps(k))//": "//status%message
            call fail(status)
            return
         end if
         call wall_clock(t1)
         if (.not. quiet) then
            associate(r => levels(k)%res)
               write(output_unit, '(a)') "femcod resolution: NP = "//int_str(levels(k)%np)//" ("//method//", pixel "// &
                  sig_str(levels(k)%pixel, 6)//" nm): "//int_str(r%nsteps)//" steps, "// &
                  int_str(r%step_contacts(r%nsteps))//" contacts, load "//sig_str(r%step_load(r%nsteps), 6)// &
                  " nN, area ~ load^"//sig_str(levels(k)%exponent, 4)//", "//sig_str(t1 - t0, 3)//" s"
            end associate
         end if
      end do
      call extrapolate_levels(levels)
      texts = resolution_texts(levels, method, deck%np*deck%pixel, friction)
      call write_file_set(names, texts, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      if (.not. quiet) then
         do k = 1, size(levels)
            if (levels(k)%coarser_np > 0) write(output_unit, '(a)') "  Richardson "//int_str(levels(k)%coarser_np)// &
               " & "//int_str(levels(k)%np)//": area ~ load^"//sig_str(fitted_exponent(levels(k)%richardson_load, &
               levels(k)%richardson_area), 4)
            write(output_unit, '(a)') "  McCool NP = "//int_str(levels(k)%np)//": area ~ load^"// &
               sig_str(fitted_exponent(levels(k)%res%step_load(1:levels(k)%res%nsteps), levels(k)%mccool_area), 4)// &
               " (eta "//sig_str(levels(k)%mccool%density, 4)//" /nm^2, R "//sig_str(levels(k)%mccool%radius, 4)// &
               " nm, sigma_s "//sig_str(levels(k)%mccool%sigma, 4)//" nm)"
         end do
         if (friction) call print_common_friction(levels, shear(2))
         write(output_unit, '(a)') "  wrote "//prefix//".resolution.csv, .powerlaw.csv, .estimates.csv, .hardness.csv, "// &
            ".hardness_capped.csv and 5 SVG figures"
      end if
   contains
      subroutine usage(message)
         character(len=*), intent(in) :: message
         write(error_unit, '(a)') "femcod resolution: "//message//" (femcod resolution --help)"
         code = STATUS_USAGE
      end subroutine usage
      subroutine fail(st)
         type(status_type), intent(in) :: st
         write(error_unit, '(a)') "femcod resolution: "//st%message
         code = st%code
      end subroutine fail
   end subroutine resolution_command

   !> The friction coefficient of every level at the largest load L all of them reached
   !> (nN), from the history row that ends the step holding L: within that step the
   !> contacts are the row's and their forces linear in the load, so F_t(L) = F_t(row) -
   !> alpha (F(row) - L), exact where no pixel crosses the shear cap within the step.
   subroutine print_common_friction(levels, alpha)
      type(resolution_level), intent(in) :: levels(:)
      real(dp), intent(in) :: alpha
      real(dp) :: common, ft
      integer :: k, i
      common = huge(1.0_dp)
      do k = 1, size(levels)
         common = min(common, levels(k)%res%step_load(levels(k)%res%nsteps))
      end do
      write(output_unit, '(a)') "  friction coefficient at "//sig_str(common, 6)//" nN (the largest load every "// &
         "level reached):"
      do k = 1, size(levels)
         associate(r => levels(k)%res)
            i = 1
            do while (r%step_load(i) < common .and. i < r%nsteps)
               i = i + 1
            end do
            ft = r%step_friction(i) - alpha*(r%step_load(i) - common)
            write(output_unit, '(a)') "    NP = "//int_str(levels(k)%np)//" (pixel "//sig_str(levels(k)%pixel, 4)// &
               " nm): "//sig_str(ft/common, 6)
         end associate
      end do
   end subroutine print_common_friction

   !> The CSV and SVG texts of a resolution study, in the order of the names above; with
   !> `friction`, the shear model's columns in the first.
   function resolution_texts(levels, method, side, friction) result(texts)
      type(resolution_level), intent(in) :: levels(:)
      character(len=*), intent(in) :: method
      real(dp), intent(in) :: side
      logical, intent(in) :: friction
      type(string_type) :: texts(10)
      type(text_builder) :: b(5)
      type(svg_series), allocatable :: s1(:), s2(:), s3(:), s4(:), s5(:)
      integer :: k, i, n
      real(dp) :: a0, px2
      character(len=:), allocatable :: npk
      a0 = side**2
      call add_line(b(1), "np,method,load_nN,approach_nm,area_nm2"// &
         trim(merge(",friction_nN,friction_coefficient", "                                 ", friction)))
      call add_line(b(2), "np,exponent,prefactor")
      call add_line(b(3), "np,model,load_nN,area_nm2")
      call add_line(b(4), "np,step,area_fraction,contacts,n_above_hardness,fraction_above_hardness")
      call add_line(b(5), "np,step,load_nN,area_fraction,contacts,n_plastic,fraction_plastic")
      allocate(s1(0), s2(0), s3(0), s4(0), s5(0))
      do k = 1, size(levels)
         associate(r => levels(k)%res)
            n = r%nsteps
            npk = int_str(levels(k)%np)
            px2 = levels(k)%pixel**2
            do i = 1, n
               call add_line(b(1), npk//","//method//","//format_real(r%step_load(i))//","// &
                  format_real(r%step_approach(i))//","//format_real(r%step_contacts(i)*px2)//friction_text(i))
            end do
            call add_line(b(2), npk//","//format_real(levels(k)%exponent)//","//format_real(levels(k)%prefactor))
            do i = 1, n
               call add_line(b(3), npk//",coupled,"//format_real(r%step_load(i))//","//format_real(r%step_contacts(i)*px2))
            end do
            do i = 1, n
               call add_line(b(3), npk//",uncoupled,"//format_real(levels(k)%uncoupled_load(i))//","// &
                  format_real(levels(k)%uncoupled_area(i)))
            end do
            do i = 1, n
               call add_line(b(3), npk//",mccool,"//format_real(r%step_load(i))//","//format_real(levels(k)%mccool_area(i)))
            end do
            do i = 1, size(levels(k)%richardson_load)
               call add_line(b(3), npk//",richardson,"//format_real(levels(k)%richardson_load(i))//","// &
                  format_real(levels(k)%richardson_area(i)))
            end do
            do i = 1, n
               call add_line(b(4), npk//","//int_str(i)//","//format_real(r%step_contacts(i)*px2/a0)//","// &
                  int_str(r%step_contacts(i))//","//int_str(r%step_above_hardness(i))//","// &
                  format_real(real(r%step_above_hardness(i), dp)/max(r%step_contacts(i), 1)))
            end do
            ! Figures: loads in mN and areas in um^2 against displacement (Fig. 4.17),
            ! area fraction against apparent pressure in MPa (Fig. 4.18), the share of
            ! contacts above the hardness against the area fraction in % (Fig. 4.21).
            call add_series(s1, npk//" x "//npk, r%step_approach(1:n), r%step_load(1:n)*1.0e-6_dp)
            call add_series(s2, npk//" x "//npk, r%step_approach(1:n), r%step_contacts(1:n)*px2*1.0e-6_dp)
            call add_series(s3, "femcod "//npk//" x "//npk, r%step_load(1:n)/a0*1.0e3_dp, &
               r%step_contacts(1:n)*px2/a0, dashed=.true.)
            call add_series(s3, "McCool "//npk//" x "//npk, r%step_load(1:n)/a0*1.0e3_dp, &
               levels(k)%mccool_area/a0, markers=.false.)
            call add_series(s4, "femcod "//npk//" x "//npk, r%step_load(1:n)/a0*1.0e3_dp, &
               r%step_contacts(1:n)*px2/a0, dashed=.true.)
            if (size(levels(k)%richardson_load) > 0) call add_series(s4, "extrapolation "// &
               int_str(levels(k)%coarser_np)//" & "//npk, levels(k)%richardson_load/a0*1.0e3_dp, &
               levels(k)%richardson_area/a0, markers=.false.)
            call add_series(s5, npk//" x "//npk, r%step_contacts(1:n)*px2/a0*100, &
               100*real(r%step_above_hardness(1:n), dp)/max(r%step_contacts(1:n), 1))
            if (levels(k)%has_capped) then
               associate(c => levels(k)%capped, nc => levels(k)%capped%nsteps)
                  do i = 1, nc
                     call add_line(b(5), npk//","//int_str(i)//","//format_real(c%step_load(i))//","// &
                        format_real(c%step_contacts(i)*px2/a0)//","//int_str(c%step_contacts(i))//","// &
                        int_str(c%step_plastic(i))//","// &
                        format_real(real(c%step_plastic(i), dp)/max(c%step_contacts(i), 1)))
                  end do
                  call add_series(s5, npk//" x "//npk//", capped at H", c%step_contacts(1:nc)*px2/a0*100, &
                     100*real(c%step_plastic(1:nc), dp)/max(c%step_contacts(1:nc), 1), dashed=.true.)
               end associate
            end if
         end associate
      end do
      ! The uncoupled model of the finest level (dashed, as in Fig. 4.17).
      k = maxloc(levels%np, 1)
      n = levels(k)%res%nsteps
      call add_series(s1, "no coupling ("//int_str(levels(k)%np)//")", levels(k)%res%step_approach(1:n), &
         levels(k)%uncoupled_load*1.0e-6_dp, dashed=.true., markers=.false.)
      call add_series(s2, "no coupling ("//int_str(levels(k)%np)//")", levels(k)%res%step_approach(1:n), &
         levels(k)%uncoupled_area*1.0e-6_dp, dashed=.true., markers=.false.)
      ! In Fig. 4.18a only up to the largest load femcod reached, so that the axes fit.
      associate(keep => levels(k)%uncoupled_load <= levels(k)%res%step_load(n))
         call add_series(s3, "no coupling ("//int_str(levels(k)%np)//")", &
            pack(levels(k)%uncoupled_load, keep)/a0*1.0e3_dp, pack(levels(k)%uncoupled_area, keep)/a0, &
            dashed=.true., markers=.false.)
      end associate
      do k = 1, 4
         texts(k)%s = built_text(b(k))
      end do
      texts(5)%s = svg_multi_plot("load against displacement (thesis Fig. 4.17a)", "displacement (nm)", &
         "contact load (mN)", s1, .false., .false.)
      texts(6)%s = svg_multi_plot("area against displacement (thesis Fig. 4.17b)", "displacement (nm)", &
         "contact area (um^2)", s2, .false., .false.)
      texts(7)%s = svg_multi_plot("area fraction against pressure: femcod and McCool (Fig. 4.18a)", &
         "apparent pressure (MPa)", "fraction of the area in contact", s3, .false., .false.)
      texts(8)%s = svg_multi_plot("Richardson extrapolation, rate 1 (thesis Fig. 4.18b)", "apparent pressure (MPa)", &
         "fraction of the area in contact", s4, .false., .false.)
      texts(9)%s = svg_multi_plot("contacts above the hardness (thesis Fig. 4.21), and at it when capped", &
         "contact area / total surface area (%)", "contacts with p > H, or at H when capped (%)", s5, .false., .false.)
      texts(10)%s = built_text(b(5))
   contains
      !> ",F_t,mu" of row i of level k's history with the friction columns; "" without.
      function friction_text(i) result(t)
         integer, intent(in) :: i
         character(len=:), allocatable :: t
         t = ""
         if (friction) t = ","//format_real(levels(k)%res%step_friction(i))//","// &
            format_real(friction_coefficient(levels(k)%res%step_friction(i), levels(k)%res%step_load(i), &
            levels(k)%res%step_contacts(i)))
      end function friction_text
   end function resolution_texts

   !> One of the Fig. 3.2 panels: a summit statistic against the box size, log-log,
   !> with its fitted power law dashed.
   function summit_plot(title, ylabel, box, values, exponent, prefactor) result(svg)
      character(len=*), intent(in) :: title, ylabel
      real(dp), intent(in) :: box(:), values(:), exponent, prefactor
      character(len=:), allocatable :: svg
      type(svg_series), allocatable :: series(:)
      call add_series(series, "summits", box, values)
      call add_series(series, "fit: d^"//sig_str(exponent, 3), box, fit_line(prefactor, exponent, box), dashed=.true., &
         markers=.false.)
      svg = svg_multi_plot(title, "box size d (nm)", ylabel, series, .true., .true.)
   end function summit_plot

   !> The fitted power law at the points, or nothing when the fit failed (fewer than
   !> two positive values).
   function fit_line(prefactor, exponent, x) result(y)
      real(dp), intent(in) :: prefactor, exponent, x(:)
      real(dp), allocatable :: y(:)
      if (prefactor > 0) then
         y = prefactor*x**exponent
      else
         y = 0*x
      end if
   end function fit_line

   !> Exponent of the least-squares power law through the positive points.
   function fitted_exponent(x, y) result(e)
      real(dp), intent(in) :: x(:), y(:)
      real(dp) :: e, pre
      logical, allocatable :: keep(:)
      keep = x > 0 .and. y > 0
      call power_law_fit(pack(x, keep), pack(y, keep), e, pre)
   end function fitted_exponent

   !> The scene of a height file for a study: the heights on an elastic lower body
   !> (--young, --poisson; default 200 GPa, 0.25) against a rigid flat, as `run --lower`.
   subroutine surface_scene(parsed, input, spec)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: input
      type(scene_spec), intent(out) :: spec
      character(len=:), allocatable :: text
      spec%kind = "matrix"
      spec%label = "heights from "//input
      call get_option(parsed, "--label", spec%label)
      spec%matrix_file = input
      spec%second_file = ""
      spec%shape_on = "lower"
      call get_option(parsed, "--pixel", spec%pixel)
      call get_option(parsed, "--young", spec%young)
      call get_option(parsed, "--poisson", spec%poisson)
      call get_option(parsed, "--maxcont", spec%maxcont)
      call get_option(parsed, "--remove-plane", spec%plane)
      call get_option(parsed, "--rigid-factor", spec%rigid_factor)
      if (option_given(parsed, "--height-unit")) then
         text = ""
         call get_option(parsed, "--height-unit", text)
         spec%height_unit = text
      end if
      text = ""
      call get_option(parsed, "--rigid", text)
      if (text /= "") spec%rigid = text
   end subroutine surface_scene

   !> The problem of a study: a deck, or (a spec with a pixel size) a height file.
   subroutine study_deck(input, spec, deck, status)
      character(len=*), intent(in) :: input
      type(scene_spec), intent(in) :: spec
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      if (spec%pixel > 0 .or. is_height_file(input)) then
         call load_scene(spec, deck, status)
      else
         call read_deck(input, deck, status)
         if (status%code /= 0 .and. looks_like_height_matrix(input)) then
            status%code = STATUS_USAGE
            status%message = input//" reads as a matrix of heights, not as a deck: give --pixel D (nm) to study "// &
               "it as heights ("//status%message//")"
         end if
      end if
   end subroutine study_deck

   !> Before any work: no output names the input `input` (exit 2), an existing output is
   !> replaced only with --force and only when femcod wrote it (exit 5; see
   !> io/femcod_output_guard), and the directory takes files.
   subroutine check_outputs(names, input, force, status)
      type(string_type), intent(in) :: names(:)
      character(len=*), intent(in) :: input
      logical, intent(in) :: force
      type(status_type), intent(inout) :: status
      integer :: unit, ios
      type(string_type) :: inputs(1)
      inputs(1)%s = height_file_path(input)
      call guard_outputs(names, inputs, force, OUTPUT_RESULT, status)
      if (status%code /= 0) return
      open(newunit=unit, file=names(1)%s//".part", status="replace", action="write", iostat=ios)
      if (ios /= 0) then
         call set_error(status, STATUS_IO, names(1)%s//": cannot write (directory missing or not writable); nothing was run")
         return
      end if
      close(unit, status="delete")
   end subroutine check_outputs

   !> Progress within a level's solve, every 10 s on standard error.
   subroutine level_progress(self, step, contacts, load, elapsed)
      class(level_observer), intent(inout) :: self
      integer, intent(in) :: step, contacts
      real(dp), intent(in) :: load, elapsed
      if (self%quiet .or. elapsed - self%last_report < 10) return
      self%last_report = elapsed
      write(error_unit, '(a)') "femcod resolution: event "//int_str(step)//", "//int_str(contacts)//" contacts, load "// &
         sig_str(load, 5)//" nN, "//sig_str(elapsed, 3)//" s"
      flush(error_unit)
   end subroutine level_progress

   !> Heights for the surface studies: a height file (with --pixel) or a deck, whose
   !> composite roughness (lower surface plus the upper as it faces it) is analysed.
   subroutine study_heights(input, pixel, plane, z, d, status, height_unit, estar)
      character(len=*), intent(in) :: input
      real(dp), intent(in) :: pixel
      logical, intent(in) :: plane
      real(dp), allocatable, intent(out) :: z(:, :)
      real(dp), intent(out) :: d
      type(status_type), intent(inout) :: status
      character(len=*), intent(in) :: height_unit
      !> A deck's composite (Hertz) modulus E* (GPa), 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2;
      !> 0 for a height file, which gives no material.
      real(dp), intent(out), optional :: estar
      type(contact_problem) :: deck
      type(height_map) :: map
      integer :: k
      if (present(estar)) estar = 0
      if (pixel > 0 .or. is_height_file(input)) then
         call read_height_map(input, map, status, height_unit)
         if (status%code /= 0) return
         do k = 1, size(map%warnings)
            write(error_unit, '(a)') "femcod: warning: "//map%warnings(k)%s
         end do
         d = pixel
         if (.not. d > 0) d = map%pixel_x
         if (.not. d > 0) then
            call set_error(status, STATUS_USAGE, input//" does not give its pixel size: give --pixel D (nm)")
            return
         end if
         call move_alloc(map%z, z)
      else
         call read_deck(input, deck, status)
         if (status%code /= 0 .and. looks_like_height_matrix(input)) then
            status%code = STATUS_USAGE
            status%message = input//" reads as a matrix of heights, not as a deck: give --pixel D (nm) to study "// &
               "it as heights ("//status%message//")"
         end if
         if (status%code /= 0) return
         z = deck%lower + flip_upper(deck%upper)
         d = deck%pixel
         if (present(estar)) estar = 1/((1 - deck%poisson(1)**2)/deck%young(1) + (1 - deck%poisson(2)**2)/deck%young(2))
      end if
      if (status%code /= 0) return
      if (size(z, 1) /= size(z, 2)) then
         call set_error(status, STATUS_BAD_INPUT, input//": expected a square matrix of heights, found "// &
            int_str(size(z, 1))//" rows of "//int_str(size(z, 2))//" values")
         return
      end if
      if (size(z, 1) < 5) then
         call set_error(status, STATUS_BAD_INPUT, input//": expected at least 5 x 5 heights for a surface study, found "// &
            int_str(size(z, 1))//" x "//int_str(size(z, 2)))
         return
      end if
      if (plane) call remove_plane(z)
   end subroutine study_heights

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

   !> The options of `summits` (command "summits") and `multiscale` (its own besides).
   function surface_table(command) result(table)
      character(len=*), intent(in) :: command
      type(option_spec), allocatable :: table(:)
      table = [ &
         text_option("--output", "PREFIX", "output prefix (default: the input's name)", alias="-o"), &
         real_option("--pixel", "D", "pixel size in nm: FILE holds heights (nm), not a deck", lower=0.0_dp, &
            closed="()"), &
         integer_list_option("--sizes", "n1,...", "neighbourhood sizes (default 1, 2, 3, 4, 6, 8, 11, 16, ... up "// &
            "to N/8)", lower=1), &
         flag_option("--remove-plane", "subtract the least-squares plane"), &
         choice_option("--height-unit", "m|mm|um|nm|A|pm", "unit of the heights in files that do not state theirs "// &
            "(default nm)"), &
         flag_option("--force", "replace existing result files"), &
         flag_option("--quiet", "no summary", alias="-q")]
      if (command /= "multiscale") return
      table = [table, &
         integer_option("--template-size", "n", "neighbourhood size of the template (default: the size whose "// &
            "summit count is nearest 100, as the thesis' template)", lower=1), &
         real_list_option("--s", "s1,...", "length scaling constants (default 2.5,5,10)", lower=1.0_dp, closed="()"), &
         real_option("--min-length", "L", "finest length scale in nm (default 4: ten atomic spacings, the limit of "// &
            "the elastic solution)", lower=0.0_dp, closed="()"), &
         integer_option("--scales", "K", "the number of scales instead of --min-length", lower=1, upper=60), &
         real_option("--load", "F", "total load in nN (default 1e6, 1 mN)", lower=0.0_dp, closed="()"), &
         real_option("--estar", "E", "composite modulus in GPa for a height file (default 200); a deck gives "// &
            "its own: 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2", lower=0.0_dp, closed="()"), &
         real_list_option("--exponents", "eh,eR,eN", "override the power laws of the summit search", length=3)]
   end function surface_table

   !> Parse the options of `summits` and `multiscale` (`code` -1: help asked).
   subroutine parse_surface_options(command, args, opts, parsed, code)
      character(len=*), intent(in) :: command
      type(string_type), intent(in) :: args(:)
      type(surface_options), intent(out) :: opts
      type(parsed_options), intent(out) :: parsed
      integer, intent(out) :: code
      type(status_type) :: status
      integer :: k
      code = 0
      if (help_requested(args)) then
         code = -1
         return
      end if
      opts%input = ""
      opts%prefix = ""
      opts%height_unit = ""
      allocate(opts%sizes(0))
      call parse_options(surface_table(command), args, parsed, status)
      if (status%code == 0) then
         if (size(parsed%positional) == 0) call set_error(status, STATUS_USAGE, "no deck or height file given")
         if (size(parsed%positional) > 1) call set_error(status, STATUS_USAGE, "one input only (found '"// &
            parsed%positional(1)%s//"' and '"//parsed%positional(2)%s//"')")
      end if
      if (status%code /= 0) then
         call usage_line(command, status%message)
         code = status%code
         return
      end if
      opts%input = parsed%positional(1)%s
      call get_option(parsed, "--output", opts%prefix)
      call get_option(parsed, "--pixel", opts%pixel)
      call get_option(parsed, "--sizes", opts%sizes)
      call get_option(parsed, "--remove-plane", opts%plane)
      call get_option(parsed, "--height-unit", opts%height_unit)
      call get_option(parsed, "--force", opts%force)
      call get_option(parsed, "--quiet", opts%quiet)
      if (opts%prefix == "") opts%prefix = default_prefix(file_part(opts%input))
      ! An option the run would ignore is refused, as run does.
      do k = 1, size(opts%sizes)
         if (count(opts%sizes == opts%sizes(k)) > 1) then
            call set_error(status, STATUS_USAGE, "--sizes: "//int_str(opts%sizes(k))//" is given twice")
            exit
         end if
      end do
      if (status%code == 0 .and. opts%height_unit /= "" .and. .not. (opts%pixel > 0 .or. &
         is_height_file(opts%input))) call set_error(status, STATUS_USAGE, "--height-unit: "//opts%input// &
         " is a deck, whose heights are in nm; the unit is for height files")
      if (status%code == 0 .and. option_given(parsed, "--min-length") .and. option_given(parsed, "--scales")) &
         call set_error(status, STATUS_USAGE, "give --min-length L or --scales K, not both (the scales are K, "// &
            "or as many as reach L)")
      if (status%code /= 0) then
         call usage_line(command, status%message)
         code = status%code
      end if
   end subroutine parse_surface_options

   subroutine usage_line(command, message)
      character(len=*), intent(in) :: command, message
      write(error_unit, '(a)') "femcod "//command//": "//message//" (femcod "//command//" --help)"
   end subroutine usage_line

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
         string_type(opts%prefix//".psd.svg"), string_type(opts%prefix//".structure.svg")]
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
      allocate(texts(10))
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
            ".fractal.csv and 5 SVG figures"
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

   subroutine fail_with(command, status, code)
      character(len=*), intent(in) :: command
      type(status_type), intent(in) :: status
      integer, intent(out) :: code
      write(error_unit, '(a)') "femcod "//command//": "//status%message
      code = status%code
   end subroutine fail_with

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
      names = [string_type(opts%prefix//".multiscale.csv"), string_type(opts%prefix//".multiscale.svg")]
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
      allocate(texts(2))
      texts(1)%s = built_text(b)
      texts(2)%s = svg_multi_plot("true contact area against the smallest length scale (thesis Fig. 3.10)", &
         "smallest length scale (nm)", "true contact area (nm^2)", series, .true., .true.)
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
end module femcod_studies
