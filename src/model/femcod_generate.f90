!> Deck generators behind `femcod mkdeck`: a `deck_spec` names a surface kind and its
!> parameters; `build_deck` turns it into a deck. `verification_spec` gives the specs
!> of the decks kept in input/ (thesis Tables 4.1, 4.2, Figs. 4.14-4.16).
!>
!> Scene convention: the generated shape goes on one surface (`shape_on`), the other
!> surface is flat (0 nm). One body may be rigid (`rigid`): its modulus is
!> `rigid_factor` times the elastic body's, and the contact and interface elements get
!> the same rigid modulus (section 4.4). The default, RIGID_FACTOR = 1e10, keeps the
!> penalty's model error near 4e-11 of the approach (doc/stability.md); the decks of
!> input/ keep the thesis' THESIS_RIGID_FACTOR = 1e5 so that they are the thesis' scenes.
module femcod_generate
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_deck, only: deck_type, validate_deck
   use femcod_files, only: path_exists, path_is_directory
   use femcod_hdf5, only: h5_file, h5_open, h5_read, h5_close
   use femcod_strings, only: int_str, parse_real, format_real
   use femcod_surfaces, only: circle_punch, square_punch, sphere_cap, sinusoid_surface, weierstrass_mandelbrot, &
      self_affine_surface, remove_plane
   implicit none
   private
   public :: deck_spec, build_deck, verification_spec, VERIFICATION_DECKS, read_ascii_matrix, read_heights, RIGID_FACTOR, &
      THESIS_RIGID_FACTOR, KINDS

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
   type :: deck_spec
      character(len=:), allocatable :: kind, label, matrix_file
      !> With kind "matrix": heights of the other surface from a second file ("": flat).
      character(len=:), allocatable :: second_file
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
   end type deck_spec

contains

   !> Build a deck from a spec. MAXCONT 0 means a default: the punch pixels for
   !> punches, NP**2 for a flat, 5 % of NP**2 otherwise.
   subroutine build_deck(spec, deck, status)
      type(deck_spec), intent(in) :: spec
      type(deck_type), intent(out) :: deck
      type(status_type), intent(inout) :: status
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
         call read_heights(spec%matrix_file, shape, status)
         if (status%code /= 0) return
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
      deck%label = spec%label
      deck%np = np
      deck%pixel = spec%pixel
      if (spec%maxcont > 0) then
         deck%maxcont = spec%maxcont
      else if (npunch > 0) then
         deck%maxcont = npunch
      else if (spec%kind == "flat") then
         deck%maxcont = np*np
      else
         ! 5 % of the pixels: rough contacts rarely go further, and the legacy solver's
         ! skyline grows as MAXCONT**2.
         deck%maxcont = max(1, np*np/20)
      end if
      deck%young = spec%young
      deck%poisson = spec%poisson
      select case (spec%rigid)
      case ("upper")
         deck%young(2) = spec%young*spec%rigid_factor
         deck%young(3) = spec%young*spec%rigid_factor
      case ("lower")
         deck%young(1) = spec%young*spec%rigid_factor
         deck%young(3) = spec%young*spec%rigid_factor
      case ("none")
         deck%young(3) = spec%young*spec%rigid_factor
      case default
         call set_error(status, STATUS_BAD_INPUT, "mkdeck: --rigid must be upper, lower or none")
         return
      end select
      allocate(deck%lower(np, np), deck%upper(np, np))
      deck%lower = 0
      deck%upper = 0
      select case (spec%shape_on)
      case ("upper")
         deck%upper = shape
      case ("lower")
         deck%lower = shape
      case default
         call set_error(status, STATUS_BAD_INPUT, "mkdeck: --shape-on must be upper or lower")
         return
      end select
      if (spec%kind == "matrix" .and. allocated(spec%second_file)) then
         if (spec%second_file /= "") then
            call read_heights(spec%second_file, shape, status)
            if (status%code /= 0) return
            if (size(shape, 1) /= np) then
               call set_error(status, STATUS_BAD_INPUT, spec%second_file//": expected "//int_str(np)//" x "// &
                  int_str(np)//" heights as in "//spec%matrix_file//", found "//int_str(size(shape, 1))//" x "// &
                  int_str(size(shape, 2)))
               return
            end if
            if (spec%plane) call remove_plane(shape)
            shape = shape - minval(shape)
            if (spec%shape_on == "upper") then
               deck%lower = shape
            else
               deck%upper = shape
            end if
         end if
      end if
      call validate_deck(deck, status)
   contains
      pure real(dp) function pick(value, default)
         real(dp), intent(in) :: value, default
         pick = value
         if (value <= 0) pick = default
      end function pick
   end subroutine build_deck

   !> The spec of a verification deck of input/ by name; an error for an unknown name.
   subroutine verification_spec(name, spec, status)
      character(len=*), intent(in) :: name
      type(deck_spec), intent(out) :: spec
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

   !> Heights (nm) from `FILE` (an ASCII matrix) or `FILE.h5:/path` (a square 2-D HDF5
   !> dataset, C order: data[i, j] is row i, column j; any numeric type).
   subroutine read_heights(path, z, status)
      character(len=*), intent(in) :: path
      real(dp), allocatable, intent(out) :: z(:, :)
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      integer :: colon
      colon = index(path, ":/", back=.true.)
      if (colon == 0) then
         call read_ascii_matrix(path, z, status)
         return
      end if
      associate(fname => path(1:colon - 1), dataset => path(colon + 1:))
         if (path_is_directory(fname) .or. .not. path_exists(fname)) then
            call set_error(status, STATUS_BAD_INPUT, fname//": expected an HDF5 file of heights, found none")
            return
         end if
         call h5_open(fname, file, status, STATUS_BAD_INPUT)
         call h5_read(file, dataset, z, status, STATUS_BAD_INPUT)
         call h5_close(file, status)
         if (status%code /= 0) return
         if (size(z, 1) /= size(z, 2) .or. size(z) == 0) then
            call set_error(status, STATUS_BAD_INPUT, path//": expected a square matrix of heights, found "// &
               int_str(size(z, 1))//" x "//int_str(size(z, 2)))
            return
         end if
         if (.not. all(ieee_is_finite(z))) then
            call set_error(status, STATUS_BAD_INPUT, path//": expected finite heights (nm), found NaN or Inf")
            return
         end if
      end associate
   end subroutine read_heights

   !> Read an ASCII height matrix (nm), one image row per line, values separated by
   !> blanks, tabs or commas, lines starting with '#' ignored (Gwyddion export). The
   !> matrix must be square.
   subroutine read_ascii_matrix(path, z, status)
      character(len=*), intent(in) :: path
      real(dp), allocatable, intent(out) :: z(:, :)
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: line
      real(dp), allocatable :: row(:), rows(:, :)
      integer :: unit, ios, nrow, ncol, lineno
      logical :: ok
      if (path_is_directory(path) .or. .not. path_exists(path)) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a height-matrix file, found none")
         return
      end if
      open(newunit=unit, file=path, action="read", status="old", iostat=ios)
      if (ios /= 0) then
         call set_error(status, STATUS_BAD_INPUT, path//": cannot open the height matrix")
         return
      end if
      nrow = 0
      ncol = 0
      lineno = 0
      allocate(rows(0, 0))
      do
         call read_line(unit, line, ios)
         if (ios /= 0) exit
         lineno = lineno + 1
         if (len_trim(line) == 0) cycle
         if (adjustl(line(1:1)) == "#" .or. line(1:1) == "#") cycle
         call split_reals(line, row, ok)
         if (.not. ok) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)// &
               ": expected a row of finite numbers (nm), found '"//line(1:min(len(line), 40))//"'")
            close(unit)
            return
         end if
         if (nrow == 0) then
            ncol = size(row)
            deallocate(rows)
            allocate(rows(ncol, ncol))
         end if
         if (size(row) /= ncol) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)//": expected "// &
               int_str(ncol)//" values as in the first row, found "//(int_str(size(row))))
            close(unit)
            return
         end if
         nrow = nrow + 1
         if (nrow > ncol) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//int_str(lineno)// &
               ": expected a square matrix of "//int_str(ncol)//" rows, found more rows")
            close(unit)
            return
         end if
         rows(:, nrow) = row
      end do
      close(unit)
      if (nrow == 0 .or. nrow /= ncol) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected a square matrix of heights, found "// &
            int_str(nrow)//" rows of "//int_str(ncol)//" values")
         return
      end if
      z = transpose(rows)
   end subroutine read_ascii_matrix

   !> Read one line of any length.
   subroutine read_line(unit, line, ios)
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: line
      integer, intent(out) :: ios
      character(len=4096) :: buf
      integer :: nread
      line = ""
      do
         read(unit, '(a)', advance="no", iostat=ios, size=nread) buf
         line = line//buf(1:nread)
         if (ios /= 0) exit
      end do
      if (is_iostat_eor(ios)) ios = 0
      if (len(line) > 0) then
         if (line(len(line):len(line)) == achar(13)) line = line(1:len(line) - 1)
      end if
   end subroutine read_line

   !> Split a line into reals.
   subroutine split_reals(line, values, ok)
      character(len=*), intent(in) :: line
      real(dp), allocatable, intent(out) :: values(:)
      logical, intent(out) :: ok
      integer :: i, start, n
      real(dp) :: v
      real(dp), allocatable :: tmp(:)
      allocate(tmp(len(line)/2 + 1))
      n = 0
      ok = .true.
      i = 1
      do while (i <= len(line))
         if (is_sep(line(i:i))) then
            i = i + 1
            cycle
         end if
         start = i
         do while (i <= len(line))
            if (is_sep(line(i:i))) exit
            i = i + 1
         end do
         call parse_real(line(start:i - 1), v, ok)
         if (.not. ok) return
         n = n + 1
         tmp(n) = v
      end do
      values = tmp(1:n)
      ok = n > 0
   contains
      pure logical function is_sep(c)
         character(len=1), intent(in) :: c
         is_sep = c == " " .or. c == achar(9) .or. c == "," .or. c == achar(13)
      end function is_sep
   end subroutine split_reals
end module femcod_generate
