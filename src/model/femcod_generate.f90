!> Scene generators behind `femcod mkdeck`: a `scene_spec` names a surface kind and its
!> parameters; `build_problem` turns it into a contact problem (no I/O: the heights of
!> a "matrix" scene come in as an array, read by io/femcod_heights). `verification_spec` gives the specs
!> of the decks kept in input/ (thesis Tables 4.1, 4.2, Figs. 4.14-4.16).
!>
!> Scene convention: the generated shape goes on one surface (`shape_on`), the other
!> surface is flat (0 nm). One body may be rigid (`rigid`): its modulus is
!> `rigid_factor` times the elastic body's, and the contact and interface elements get
!> the same rigid modulus (section 4.4). The default, RIGID_FACTOR = 1e10, keeps the
!> penalty's model error near 4e-11 of the approach (doc/stability.md); the decks of
!> input/ keep the thesis' THESIS_RIGID_FACTOR = 1e5 so that they are the thesis' scenes.
module femcod_generate
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_USAGE
   use femcod_problem, only: contact_problem, validate_problem
   use femcod_strings, only: int_str, format_real
   use femcod_surfaces, only: circle_punch, square_punch, sphere_cap, sinusoid_surface, weierstrass_mandelbrot, &
      self_affine_surface, remove_plane
   implicit none
   private
   public :: scene_header, rough_maxcont, check_scene_spec
   public :: scene_spec, build_problem, verification_spec, VERIFICATION_DECKS, RIGID_FACTOR, THESIS_RIGID_FACTOR, KINDS, &
      paraboloid_problem

   !> Modulus ratio of a rigid body to the elastic one (thesis section 4.4).
   real(dp), parameter :: RIGID_FACTOR = 1.0e10_dp, THESIS_RIGID_FACTOR = 1.0e5_dp

   character(len=*), parameter :: KINDS(8) = [character(len=12) :: "circle-punch", "square-punch", "sphere", &
      "flat", "sinusoid", "wm", "self-affine", "matrix"]

   !> Names of the decks in input/ (without `.deck`).
   character(len=*), parameter :: VERIFICATION_DECKS(12) = [character(len=20) :: &
      "circle_punch_d1", "circle_punch_d3", "circle_punch_d9", &
      "square_punch_n1", "square_punch_n3", "square_punch_n9", "square_punch_n27", &
      "sphere_d4", "sphere_d2", "sphere_d1", "sphere_d05", "rough_selfaffine_32"]

   !> What to generate. Lengths in nm, moduli in GPa.
   type :: scene_spec
      character(len=:), allocatable :: kind, label, matrix_file
      !> With kind "matrix": heights of the other surface from a second file ("": flat),
      !> and the unit of heights in files that do not state theirs ("": nm).
      character(len=:), allocatable :: second_file
      character(len=8) :: height_unit = ""
      integer :: np = 0, maxcont = 0, seed = 1, ridges = 10
      real(dp) :: pixel = 0
      real(dp) :: young = 200, poisson = 0.25_dp
      character(len=5) :: shape_on = "upper", rigid = "upper"
      !> Modulus of the rigid body and of the contact/interface elements over the elastic one.
      real(dp) :: rigid_factor = RIGID_FACTOR
      !> Punch radius / sphere radius, punch area (nm^2, 0: pi R^2), punch height.
      real(dp) :: radius = 0, area = 0, height = 0
      !> Self-affine: Hurst exponent and rms height.
      real(dp) :: hurst = 0.8_dp, rms = 1
      !> Sinusoid eq. (3.3): amplitude A and length scale w in z = A cos(x/w) cos(y/w).
      real(dp) :: amplitude = 1, scale = 10
      !> Weierstrass-Mandelbrot eq. (3.6).
      real(dp) :: ds = 2.4_dp, g = 1.36e-2_dp, gamma = 1.5_dp, lmax = 1000, lmin = 1
      logical :: plane = .false.
      !> Height files: N x N blocks of heights averaged into one pixel (1: none).
      integer :: average = 1
   end type scene_spec

contains

   !> Build a problem from a spec. MAXCONT 0 means a default: the punch pixels for
   !> punches, NP**2 for a flat, 5 % of NP**2 otherwise. A "matrix" scene takes its
   !> heights (nm) from `heights` and, when not empty, the other surface's from `second`
   !> (io/femcod_heights reads them from the spec's files).
   subroutine build_problem(spec, problem, status, heights, second)
      type(scene_spec), intent(in) :: spec
      type(contact_problem), intent(out) :: problem
      type(status_type), intent(inout) :: status
      real(dp), intent(in), optional :: heights(:, :), second(:, :)
      real(dp), allocatable :: shape(:, :)
      integer :: npunch, np
      real(dp) :: area
      np = spec%np
      if (spec%kind /= "matrix") then
         if (np <= 0) then
            call set_error(status, STATUS_BAD_INPUT, "mkdeck: --np must be a positive integer")
            return
         end if
      end if
      if (.not. spec%pixel > 0) then
         call set_error(status, STATUS_BAD_INPUT, "mkdeck: --pixel must be a positive size in nm")
         return
      end if
      npunch = 0
      select case (spec%kind)
      case ("circle-punch")
         allocate(shape(np, np))
         area = spec%area
         if (area <= 0) area = acos(-1.0_dp)*spec%radius**2
         call circle_punch(np, spec%pixel, area, pick(spec%height, spec%radius), shape, npunch, status)
      case ("square-punch")
         allocate(shape(np, np))
         call square_punch(np, pick(spec%height, np*spec%pixel/3), shape, status)
         npunch = (np/3)**2
      case ("sphere")
         allocate(shape(np, np))
         call sphere_cap(np, spec%pixel, spec%radius, shape)
      case ("flat")
         allocate(shape(np, np))
         shape = spec%height
      case ("sinusoid")
         allocate(shape(np, np))
         call sinusoid_surface(np, spec%pixel, spec%amplitude, spec%scale, shape)
      case ("wm")
         allocate(shape(np, np))
         call weierstrass_mandelbrot(np, spec%pixel, spec%ds, spec%g, spec%gamma, spec%lmax, spec%lmin, &
            spec%ridges, spec%seed, shape)
      case ("self-affine")
         allocate(shape(np, np))
         call self_affine_surface(np, spec%pixel, spec%hurst, spec%rms, spec%seed, shape)
      case ("matrix")
         if (.not. present(heights)) then
            call set_error(status, STATUS_BAD_INPUT, "mkdeck: a matrix scene needs its heights")
            return
         end if
         shape = heights
         np = size(shape, 1)
      case default
         call set_error(status, STATUS_BAD_INPUT, "mkdeck: unknown kind '"//spec%kind//"'")
      end select
      if (status%code /= 0) return
      if (spec%plane) call remove_plane(shape)
      if (spec%kind /= "flat" .and. spec%kind /= "circle-punch" .and. spec%kind /= "square-punch" .and. &
         spec%kind /= "sphere") then
         ! Rough surfaces: their lowest point at 0 nm, so heights read as protrusions.
         shape = shape - minval(shape)
      end if
      call scene_header(spec, np, npunch, problem, status)
      if (status%code /= 0) return
      allocate(problem%lower(np, np), problem%upper(np, np))
      problem%lower = 0
      problem%upper = 0
      select case (spec%shape_on)
      case ("upper")
         problem%upper = shape
      case ("lower")
         problem%lower = shape
      case default
         call set_error(status, STATUS_BAD_INPUT, "mkdeck: --shape-on must be upper or lower")
         return
      end select
      if (spec%kind == "matrix" .and. present(second)) then
         if (size(second) > 0) then
            shape = second
            if (size(shape, 1) /= np) then
               call set_error(status, STATUS_BAD_INPUT, spec%second_file//": expected "//int_str(np)//" x "// &
                  int_str(np)//" heights as in "//spec%matrix_file//", found "//int_str(size(shape, 1))//" x "// &
                  int_str(size(shape, 2)))
               return
            end if
            if (spec%plane) call remove_plane(shape)
            shape = shape - minval(shape)
            if (spec%shape_on == "upper") then
               problem%lower = shape
            else
               problem%upper = shape
            end if
         end if
      end if
      call validate_problem(problem, status)
   contains
      pure real(dp) function pick(value, default)
         real(dp), intent(in) :: value, default
         pick = value
         if (value <= 0) pick = default
      end function pick
   end subroutine build_problem

   !> A spec asked for on the command line, checked before anything is made or read:
   !> every size its kind needs is given (a sphere without --radius would be a flat deck
   !> labelled sphere), the grid suits the kind, MAXCONT fits the grid, the label is one
   !> line, and no option is given that the kind would ignore. STATUS_USAGE (exit 2).
   subroutine check_scene_spec(spec, status)
      type(scene_spec), intent(in) :: spec
      type(status_type), intent(inout) :: status
      if (status%code /= 0) return
      if (spec%kind /= "matrix" .and. spec%np <= 0) then
         call refuse(spec%kind//" needs --np N (pixels per side)")
      else if (spec%kind /= "matrix" .and. .not. spec%pixel > 0) then
         call refuse(spec%kind//" needs --pixel D (the pixel size, nm)")
      else if (spec%kind == "sphere" .and. .not. spec%radius > 0) then
         call refuse("sphere needs --radius R (nm): without it the deck would be flat")
      else if (spec%kind == "circle-punch" .and. .not. (spec%radius > 0 .or. (spec%area > 0 .and. spec%height > 0))) &
         then
         call refuse("circle-punch needs its size: --radius R (nm; area pi R^2, height R), or --area A "// &
            "(nm^2) with --height H (nm); without them the deck would be flat")
      else if (spec%kind == "circle-punch" .and. mod(spec%np, 2) /= 1) then
         call refuse("circle-punch needs an odd --np (the punch is centred on a pixel), found "// &
            int_str(spec%np))
      else if (spec%kind == "square-punch" .and. mod(spec%np, 3) /= 0) then
         call refuse("square-punch needs --np divisible by 3 (the punch is the central NP/3 x NP/3 "// &
            "pixels), found "//int_str(spec%np))
      else if (spec%kind /= "matrix" .and. spec%maxcont > 0 .and. int(spec%maxcont, kind(1_8)) > &
         int(spec%np, kind(1_8))**2) then
         call refuse("--maxcont "//int_str(spec%maxcont)//" is more than the grid's "//int_str(spec%np)//"^2 = "// &
            int_str(spec%np*spec%np)//" pixels")
      else if (spec%kind == "matrix" .and. spec%matrix_file == "") then
         call refuse("matrix needs --file FILE (an ASCII matrix of heights, a Gwyddion export or FILE.h5:/DATASET)")
      else if (scan(spec%label, achar(10)//achar(13)) > 0) then
         call refuse("--label must be a single line (it is the deck's first line)")
      else if (spec%kind /= "matrix" .and. spec%height_unit /= "") then
         call refuse("--height-unit with mkdeck "//spec%kind//": the unit of heights read from a file (kind "// &
            "matrix); a generated surface is in nm")
      end if
   contains
      subroutine refuse(message)
         character(len=*), intent(in) :: message
         call set_error(status, STATUS_USAGE, message)
      end subroutine refuse
   end subroutine check_scene_spec

   !> A scene's problem without its heights: label, NP, pixel, MAXCONT (MAXCONT 0 in the
   !> spec: `npunch` for punches, NP**2 for a flat, 5 % of NP**2 otherwise) and the
   !> materials, a rigid body and the interface elements at `rigid_factor` times E. What
   !> femcod-mpi needs of a surface it makes on its ranks (femcod_mpi_generate).
   subroutine scene_header(spec, np, npunch, problem, status)
      type(scene_spec), intent(in) :: spec
      integer, intent(in) :: np, npunch
      type(contact_problem), intent(inout) :: problem
      type(status_type), intent(inout) :: status
      problem%label = spec%label
      problem%np = np
      problem%pixel = spec%pixel
      if (spec%maxcont > 0) then
         problem%maxcont = spec%maxcont
      else if (npunch > 0) then
         problem%maxcont = npunch
      else if (spec%kind == "flat") then
         problem%maxcont = np*np
      else
         problem%maxcont = rough_maxcont(np)
      end if
      problem%young = spec%young
      problem%poisson = spec%poisson
      select case (spec%rigid)
      case ("upper")
         problem%young(2) = spec%young*spec%rigid_factor
         problem%young(3) = spec%young*spec%rigid_factor
      case ("lower")
         problem%young(1) = spec%young*spec%rigid_factor
         problem%young(3) = spec%young*spec%rigid_factor
      case ("none")
         problem%young(3) = spec%young*spec%rigid_factor
      case default
         call set_error(status, STATUS_BAD_INPUT, "mkdeck: --rigid must be upper, lower or none")
         return
      end select
   end subroutine scene_header

   !> The MAXCONT of a rough scene of NP^2 pixels when none is given: 5 % of the pixels.
   !> Rough contacts rarely go further, and the legacy solver's skyline grows as MAXCONT**2.
   pure integer function rough_maxcont(np)
      integer, intent(in) :: np
      rough_maxcont = max(1, np*np/20)
   end function rough_maxcont

   !> The spec of a verification deck of input/ by name; an error for an unknown name.
   subroutine verification_spec(name, spec, status)
      character(len=*), intent(in) :: name
      type(scene_spec), intent(out) :: spec
      type(status_type), intent(inout) :: status
      integer :: m
      spec%young = 200
      spec%poisson = 0.25_dp
      spec%shape_on = "upper"
      spec%rigid = "upper"
      spec%rigid_factor = THESIS_RIGID_FACTOR
      spec%maxcont = 0
      select case (name)
      case ("circle_punch_d1", "circle_punch_d3", "circle_punch_d9")
         ! Table 4.1: R = 2.5 nm punch of 21 pixels at d = 1 nm, area kept at 21 nm^2.
         m = 1
         if (name == "circle_punch_d3") m = 3
         if (name == "circle_punch_d9") m = 9
         spec%kind = "circle-punch"
         spec%np = 11*m
         spec%pixel = 1.0_dp/m
         spec%radius = 2.5_dp
         spec%area = 21
         spec%label = "circular rigid punch R=2.5 nm, 21 nm^2, d=1/"//int_str(m)//" nm, NP="// &
            int_str(11*m)//", E=200 GPa nu=0.25 half-space: thesis Table 4.1, Fig. 4.10"
      case ("square_punch_n1", "square_punch_n3", "square_punch_n9", "square_punch_n27")
         ! Table 4.2: 10 nm square punch in a 30 nm region, NP = 3, 9, 27, 81.
         read(name(15:), *) m
         spec%kind = "square-punch"
         spec%np = 3*m
         spec%pixel = 30.0_dp/(3*m)
         spec%label = "square rigid punch 10 nm in a 30 nm region, "//int_str(m*m)//" punch pixels, NP="// &
            int_str(3*m)//", E=200 GPa nu=0.25 half-space: thesis Table 4.2, Fig. 4.12"
      case ("sphere_d4", "sphere_d2", "sphere_d1", "sphere_d05")
         ! Figs. 4.14-4.16: rigid sphere R = 15 nm, 30 nm region, pixels 4, 2, 1, 0.5 nm.
         select case (name)
         case ("sphere_d4")
            spec%pixel = 4
         case ("sphere_d2")
            spec%pixel = 2
         case ("sphere_d1")
            spec%pixel = 1
         case default
            spec%pixel = 0.5_dp
         end select
         spec%kind = "sphere"
         spec%radius = 15
         spec%np = ceiling(30/spec%pixel - 1.0e-9_dp)
         ! MAXCONT: the pixels within 10 nm of the apex (the contact radius is about
         ! 9.3 nm at the thesis' largest load, 18000 nN).
         spec%maxcont = pixels_within(spec%np, spec%pixel, 10.0_dp)
         spec%label = "rigid sphere R=15 nm, 30 nm region, d="//format_real(spec%pixel)//" nm, NP="// &
            int_str(spec%np)//", E=200 GPa nu=0.25 half-space: thesis Figs. 4.14-4.16 (Hertz)"
      case ("rough_selfaffine_32")
         spec%kind = "self-affine"
         spec%np = 32
         spec%pixel = 10
         spec%hurst = 0.8_dp
         spec%rms = 3
         spec%seed = 1
         spec%shape_on = "lower"
         spec%rigid = "upper"
         spec%maxcont = 100
         spec%label = "self-affine rough surface H=0.8 rms=3 nm seed=1, 32x32 pixels of 10 nm, E=200 GPa nu=0.25, "// &
            "against a rigid flat: a small rough example (section 4.5 style)"
      case default
         call set_error(status, STATUS_BAD_INPUT, "mkdeck: unknown verification deck '"//name//"'")
      end select
   end subroutine verification_spec

   !> Pixels whose centres lie within `radius` of the grid centre.
   pure integer function pixels_within(np, pixel, radius)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, radius
      integer :: i, j
      real(dp) :: c
      c = (np + 1)/2.0_dp
      pixels_within = 0
      do j = 1, np
         do i = 1, np
            if (((i - c)**2 + (j - c)**2)*pixel**2 < radius**2) pixels_within = pixels_within + 1
         end do
      end do
   end function pixels_within

   !> A rigid paraboloid z = -r^2/(2 radius) (nm) over an elastic flat (E = young GPa,
   !> nu = 0, a rigid contact material), np x np pixels of `pixel` nm, centred between the
   !> middle pixels: the adhesion checks' sphere (Maugis-Dugdale is a paraboloid's theory).
   function paraboloid_problem(np, pixel, radius, young) result(deck)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, radius, young
      type(contact_problem) :: deck
      integer :: i, j
      real(dp) :: c
      deck%label = "paraboloid R = "//format_real(radius)//" nm"
      deck%np = np
      deck%pixel = pixel
      deck%maxcont = np**2
      deck%young = [young, 1.0e300_dp, 1.0e300_dp]
      deck%poisson = 0
      allocate(deck%lower(np, np), deck%upper(np, np))
      deck%lower = 0
      c = (np + 1)/2.0_dp
      do j = 1, np
         do i = 1, np
            deck%upper(i, j) = -((i - c)**2 + (j - c)**2)*pixel**2/(2*radius)
         end do
      end do
   end function paraboloid_problem
end module femcod_generate
