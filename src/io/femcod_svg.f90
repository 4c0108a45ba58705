!> SVG figures written by femcod itself (no plotting dependency): x-y plots on linear
!> or logarithmic axes with an optional fitted power law, and maps (pressure, gap,
!> plastic displacement, stick and slip) with a colour bar, in the manner of the
!> thesis' figures 4.16-4.19. Each function returns
!> the whole document as a string; writing it is the caller's business.
module femcod_svg
   use femcod_kinds, only: dp
   use femcod_strings, only: int_str, sig_str, xml_escape, text_builder, add_text, built_text
   use femcod_png, only: png_indexed, base64
   implicit none
   private
   public :: svg_plot, svg_pressure_map, svg_map, svg_stick_slip_map, nice_ticks, svg_series, svg_multi_plot, add_series
   public :: BLOCK_LARGEST, BLOCK_SMALLEST

   !> How a map larger than its picture is shown by blocks (svg_map): each block's
   !> largest value, or its smallest.
   integer, parameter :: BLOCK_LARGEST = 1, BLOCK_SMALLEST = 2

   !> One curve of a multi-series plot: legend label, points, dashed line, markers.
   type :: svg_series
      character(len=:), allocatable :: label
      real(dp), allocatable :: x(:), y(:)
      logical :: dashed = .false., markers = .true.
   end type svg_series

   character(len=1), parameter :: nl = new_line("a")
   !> Plot frame (px): width, height and margins left, right, top, bottom.
   real(dp), parameter :: w = 640, h = 480, ml = 90, mr = 30, mt = 50, mb = 70

contains

   !> A line plot of y against x with markers. `logx`/`logy` use decades (values <= 0
   !> are left out). With `exponent` and `prefactor` the power law y = prefactor x^exponent
   !> is drawn dashed and its exponent written in the legend.
   function svg_plot(title, xlabel, ylabel, x, y, logx, logy, exponent, prefactor) result(svg)
      character(len=*), intent(in) :: title, xlabel, ylabel
      real(dp), intent(in) :: x(:), y(:)
      logical, intent(in) :: logx, logy
      real(dp), intent(in), optional :: exponent, prefactor
      character(len=:), allocatable :: svg
      real(dp), allocatable :: tx(:), ty(:), xt(:), yt(:)
      logical, allocatable :: keep(:)
      real(dp) :: x0, x1, y0, y1, px, py, xf, yf
      integer :: k, m
      character(len=:), allocatable :: path
      type(text_builder) :: points
      real(dp) :: last(2)
      allocate(keep(size(x)))
      keep = .true.
      if (logx) keep = keep .and. x > 0
      if (logy) keep = keep .and. y > 0
      tx = pack(x, keep)
      ty = pack(y, keep)
      if (logx) tx = log10(tx)
      if (logy) ty = log10(ty)
      svg = header(title)
      if (size(tx) == 0) then
         svg = svg//text(w/2, h/2, "no data", "middle", 14)//"</svg>"//nl
         return
      end if
      call axis_range(minval(tx), maxval(tx), logx, x0, x1, xt)
      call axis_range(minval(ty), maxval(ty), logy, y0, y1, yt)
      svg = svg//axes(x0, x1, y0, y1, xt, yt, logx, logy, xlabel, ylabel)
      ! Data: a polyline and markers. Beyond 2000 points a point that moves the line by
      ! less than half a pixel from the last one drawn is left out (the first and the
      ! last are kept): the line looks the same and the file stays small at any number
      ! of steps.
      last = [-huge(1.0_dp), -huge(1.0_dp)]
      do k = 1, size(tx)
         call to_pixels([x0, x1, y0, y1], tx(k), ty(k), px, py)
         if (size(tx) > 2000 .and. k > 1 .and. k < size(tx)) then
            if (abs(px - last(1)) < 0.5_dp .and. abs(py - last(2)) < 0.5_dp) cycle
         end if
         last = [px, py]
         call add_text(points, fmt(px)//","//fmt(py)//" ")
      end do
      svg = svg//'<polyline fill="none" stroke="#1f4e9c" stroke-width="1.5" points="'//built_text(points)//'"/>'//nl
      m = max(1, size(tx)/200)
      do k = 1, size(tx), m
         call to_pixels([x0, x1, y0, y1], tx(k), ty(k), px, py)
         svg = svg//'<circle cx="'//fmt(px)//'" cy="'//fmt(py)//'" r="2.5" fill="#1f4e9c"/>'//nl
      end do
      svg = svg//'<line x1="'//fmt(w - mr - 190)//'" y1="'//fmt(mt + 18)//'" x2="'//fmt(w - mr - 160)//'" y2="'// &
         fmt(mt + 18)//'" stroke="#1f4e9c" stroke-width="1.5"/>'//text(w - mr - 154, mt + 22.0_dp, "femcod", "start", 12)
      if (present(exponent) .and. present(prefactor)) then
         path = ""
         do k = 0, 50
            xf = x0 + (x1 - x0)*k/50
            if (logx .and. logy) then
               yf = log10(prefactor) + exponent*xf
            else
               yf = prefactor*xf**exponent
            end if
            if (yf < y0 .or. yf > y1) cycle
            call to_pixels([x0, x1, y0, y1], xf, yf, px, py)
            path = path//fmt(px)//","//fmt(py)//" "
         end do
         svg = svg//'<polyline fill="none" stroke="#c0392b" stroke-width="1.5" stroke-dasharray="6,4" points="'// &
            path//'"/>'//nl
         svg = svg//'<line x1="'//fmt(w - mr - 190)//'" y1="'//fmt(mt + 38)//'" x2="'//fmt(w - mr - 160)//'" y2="'// &
            fmt(mt + 38)//'" stroke="#c0392b" stroke-width="1.5" stroke-dasharray="6,4"/>'// &
            text(w - mr - 154, mt + 42, "fit: exponent "//sig_str(exponent, 4), "start", 12)
      end if
      svg = svg//"</svg>"//nl
   end function svg_plot

   !> Append a curve to a list (component by component: gfortran mishandles array
   !> constructors of this type built from function results).
   subroutine add_series(list, label, x, y, dashed, markers)
      type(svg_series), allocatable, intent(inout) :: list(:)
      character(len=*), intent(in) :: label
      real(dp), intent(in) :: x(:), y(:)
      logical, intent(in), optional :: dashed, markers
      type(svg_series), allocatable :: longer(:)
      integer :: n, k
      n = 0
      if (allocated(list)) n = size(list)
      allocate(longer(n + 1))
      do k = 1, n
         call move_alloc(list(k)%label, longer(k)%label)
         call move_alloc(list(k)%x, longer(k)%x)
         call move_alloc(list(k)%y, longer(k)%y)
         longer(k)%dashed = list(k)%dashed
         longer(k)%markers = list(k)%markers
      end do
      longer(n + 1)%label = label
      allocate(longer(n + 1)%x(size(x)), longer(n + 1)%y(size(y)))
      longer(n + 1)%x = x
      longer(n + 1)%y = y
      if (present(dashed)) longer(n + 1)%dashed = dashed
      if (present(markers)) longer(n + 1)%markers = markers
      call move_alloc(longer, list)
   end subroutine add_series

   !> Several curves on common axes, each in its own colour with a legend entry (the
   !> thesis' figures 3.2, 4.17, 4.18 and 4.21 put one curve per image or model on one
   !> plot). Values <= 0 are left out of a logarithmic axis.
   function svg_multi_plot(title, xlabel, ylabel, series, logx, logy) result(svg)
      character(len=*), intent(in) :: title, xlabel, ylabel
      type(svg_series), intent(in) :: series(:)
      logical, intent(in) :: logx, logy
      character(len=:), allocatable :: svg
      character(len=7), parameter :: palette(8) = [character(len=7) :: "#1f4e9c", "#c0392b", "#27ae60", &
         "#8e44ad", "#d35400", "#16a085", "#7f8c8d", "#2c3e50"]
      type(svg_series), allocatable :: kept(:)
      real(dp), allocatable :: xt(:), yt(:)
      logical, allocatable :: keep(:)
      real(dp) :: x0, x1, y0, y1, lo_x, hi_x, lo_y, hi_y, px, py
      character(len=:), allocatable :: path, dash
      character(len=7) :: c
      integer :: k, s, m
      allocate(kept(size(series)))
      lo_x = huge(1.0_dp); hi_x = -huge(1.0_dp); lo_y = huge(1.0_dp); hi_y = -huge(1.0_dp)
      do s = 1, size(series)
         keep = [(.true., k = 1, size(series(s)%x))]
         if (logx) keep = keep .and. series(s)%x > 0
         if (logy) keep = keep .and. series(s)%y > 0
         kept(s)%x = pack(series(s)%x, keep)
         kept(s)%y = pack(series(s)%y, keep)
         if (logx) kept(s)%x = log10(kept(s)%x)
         if (logy) kept(s)%y = log10(kept(s)%y)
         if (size(kept(s)%x) == 0) cycle
         lo_x = min(lo_x, minval(kept(s)%x)); hi_x = max(hi_x, maxval(kept(s)%x))
         lo_y = min(lo_y, minval(kept(s)%y)); hi_y = max(hi_y, maxval(kept(s)%y))
      end do
      svg = header(title)
      if (lo_x > hi_x) then
         svg = svg//text(w/2, h/2, "no data", "middle", 14)//"</svg>"//nl
         return
      end if
      call axis_range(lo_x, hi_x, logx, x0, x1, xt)
      call axis_range(lo_y, hi_y, logy, y0, y1, yt)
      svg = svg//axes(x0, x1, y0, y1, xt, yt, logx, logy, xlabel, ylabel)
      do s = 1, size(series)
         c = palette(mod(s - 1, size(palette)) + 1)
         dash = ""
         if (series(s)%dashed) dash = ' stroke-dasharray="6,4"'
         path = ""
         do k = 1, size(kept(s)%x)
            call to_pixels([x0, x1, y0, y1], kept(s)%x(k), kept(s)%y(k), px, py)
            path = path//fmt(px)//","//fmt(py)//" "
         end do
         if (size(kept(s)%x) > 0) svg = svg//'<polyline fill="none" stroke="'//c//'" stroke-width="1.5"'//dash// &
            ' points="'//path//'"/>'//nl
         if (series(s)%markers) then
            m = max(1, size(kept(s)%x)/60)
            do k = 1, size(kept(s)%x), m
               call to_pixels([x0, x1, y0, y1], kept(s)%x(k), kept(s)%y(k), px, py)
               svg = svg//'<circle cx="'//fmt(px)//'" cy="'//fmt(py)//'" r="2.5" fill="'//c//'"/>'//nl
            end do
         end if
         py = mt + 18 + 18*(s - 1)
         svg = svg//'<line x1="'//fmt(ml + 12)//'" y1="'//fmt(py)//'" x2="'//fmt(ml + 42)//'" y2="'//fmt(py)// &
            '" stroke="'//c//'" stroke-width="1.5"'//dash//'/>'//text(ml + 48, py + 4, xml_escape(series(s)%label), "start", 12)
      end do
      svg = svg//"</svg>"//nl
   end function svg_multi_plot

   !> The pressure map (GPa): svg_map, white off contact, each block its largest pressure.
   function svg_pressure_map(title, values, side) result(svg)
      character(len=*), intent(in) :: title
      real(dp), intent(in) :: values(:, :)
      real(dp), intent(in) :: side
      character(len=:), allocatable :: svg
      svg = svg_map(title, values, side, "GPa", "pressure", BLOCK_LARGEST, .true.)
   end function svg_pressure_map

   !> A map of `values` (in `unit`) over the NP x NP grid of side `side` (nm): a raster
   !> image (PNG, embedded as base64) on the 64-level perceptual scale from 0 to the
   !> maximum, with the axes, labels and colour bar as vectors. Row i = 0 at the top and
   !> column j = 0 at the left, the axes x = j d to the right and y = (NP - i) d upward
   !> from the bottom-left corner: as the XDMF mesh and femcod.Result.to_xarray place
   !> them (doc/results.md, "Coordinates"). With `blank_zero` a value <= 0 is white
   !> (pressure or plastic displacement: off contact, not plastic). Maps larger than 1024
   !> x 1024 are shown by blocks of f x f pixels (f = ceiling(NP/1024)), each with the
   !> largest value of its block (`rule` BLOCK_LARGEST: no contact spot disappears) or
   !> its smallest (BLOCK_SMALLEST, for gaps: no contact disappears), so the file stays
   !> near 1 MB or below at any NP (the full map is in PREFIX.h5). `quantity` names the
   !> value in that note.
   function svg_map(title, values, side, unit, quantity, rule, blank_zero) result(svg)
      character(len=*), intent(in) :: title, unit, quantity
      real(dp), intent(in) :: values(:, :)
      real(dp), intent(in) :: side
      integer, intent(in) :: rule
      logical, intent(in) :: blank_zero
      character(len=:), allocatable :: svg
      integer, parameter :: levels = 64
      integer :: k, f, palette(3, 0:levels)
      real(dp) :: vmax, size_px, x0, y0
      real(dp), allocatable :: ticks(:), block(:, :)
      integer, allocatable :: bin(:, :)
      vmax = maxval(values)
      call block_values(values, rule, f, block)
      allocate(bin(size(block, 1), size(block, 2)))
      bin = 1
      if (vmax > 0) bin = 1 + min(levels - 1, max(0, int(block/vmax*levels)))
      if (blank_zero) where (.not. block > 0) bin = 0
      palette(:, 0) = 255
      do k = 1, levels
         palette(:, k) = colour_rgb((k - 0.5_dp)/levels)
      end do
      svg = map_frame(title, bin, palette, side, f, merge("largest ", "smallest", rule == BLOCK_LARGEST)//" "// &
         quantity, x0, y0, size_px)
      do k = 0, levels - 1
         svg = svg//'<rect x="'//fmt(x0 + size_px + 40)//'" y="'//fmt(y0 + size_px*(1 - real(k + 1, dp)/levels))// &
            '" width="20" height="'//fmt(size_px/levels + 0.5_dp)//'" fill="'//colour((k + 0.5_dp)/levels)//'"/>'//nl
      end do
      svg = svg//'<rect x="'//fmt(x0 + size_px + 40)//'" y="'//fmt(y0)//'" width="20" height="'//fmt(size_px)// &
         '" fill="none" stroke="black"/>'//nl
      if (vmax > 0) then
         ticks = nice_ticks(0.0_dp, vmax)
         do k = 1, size(ticks)
            if (ticks(k) < 0 .or. ticks(k) > vmax) cycle
            svg = svg//text(x0 + size_px + 66, y0 + size_px*(1 - ticks(k)/vmax) + 4, sig_str(ticks(k), 4), "start", 11)
         end do
      end if
      svg = svg//text(x0 + size_px + 50, y0 - 10, unit, "middle", 12)
      svg = svg//text(x0 + size_px + 50, h - mb + 18, "max "//sig_str(vmax, 4), "middle", 11)
      svg = svg//"</svg>"//nl
   end function svg_map

   !> The stick and slip map of a tangential step: the contacts that stick (blue) and
   !> slip (orange), white elsewhere, on svg_map's axes; blocks of a large map show slip
   !> where any of their pixels slips, else stick where any sticks.
   function svg_stick_slip_map(title, stick, slip, side) result(svg)
      character(len=*), intent(in) :: title
      real(dp), intent(in) :: stick(:, :), slip(:, :)
      real(dp), intent(in) :: side
      character(len=:), allocatable :: svg
      integer, parameter :: palette(3, 0:2) = reshape([255, 255, 255, 49, 104, 176, 235, 125, 38], [3, 3])
      character(len=*), parameter :: names(2) = [character(len=5) :: "stick", "slip"]
      real(dp) :: size_px, x0, y0
      real(dp), allocatable :: block(:, :)
      integer, allocatable :: bin(:, :)
      integer :: f, k
      call block_values(merge(2.0_dp, merge(1.0_dp, 0.0_dp, stick > 0), slip > 0), BLOCK_LARGEST, f, block)
      bin = nint(block)
      svg = map_frame(title, bin, palette, side, f, "slip, else stick,", x0, y0, size_px)
      do k = 1, 2
         svg = svg//'<rect x="'//fmt(x0 + size_px + 30)//'" y="'//fmt(y0 + 24*(k - 1))//'" width="16" height="16" '// &
            'fill="'//rgb_hex(palette(:, k))//'" stroke="black"/>'//nl
         svg = svg//text(x0 + size_px + 52, y0 + 24*(k - 1) + 13, trim(names(k)), "start", 12)
      end do
      svg = svg//text(x0 + size_px + 30, y0 + 66, int_str(count(stick > 0))//" stick", "start", 11)
      svg = svg//text(x0 + size_px + 30, y0 + 82, int_str(count(slip > 0))//" slip", "start", 11)
      svg = svg//"</svg>"//nl
   end function svg_stick_slip_map

   !> The map by blocks of f x f pixels, f = ceiling(NP/1024) (f = 1: the map itself):
   !> each block's largest or smallest value (`rule`), on all threads.
   subroutine block_values(values, rule, f, block)
      real(dp), intent(in) :: values(:, :)
      integer, intent(in) :: rule
      integer, intent(out) :: f
      real(dp), allocatable, intent(out) :: block(:, :)
      integer, parameter :: max_image = 1024
      integer :: np, m, i, j
      np = size(values, 1)
      f = (np + max_image - 1)/max_image
      m = (np + f - 1)/f
      allocate(block(m, m))
      !$omp parallel do private(i)
      do j = 1, m
         do i = 1, m
            associate(cells => values((i - 1)*f + 1:min(np, i*f), (j - 1)*f + 1:min(np, j*f)))
               if (rule == BLOCK_LARGEST) then
                  block(i, j) = maxval(cells)
               else
                  block(i, j) = minval(cells)
               end if
            end associate
         end do
      end do
   end subroutine block_values

   !> A map's document up to its legend: the title, the image of palette colours `bin`
   !> (row 1 at the top), the note on blocks of f x f pixels (each its `shown`), and the
   !> axes x = j d to the right and y = (NP - i) d upward, 0 to `side` (nm). The image's
   !> corner (x0, y0) and side (px) for the legend.
   function map_frame(title, bin, palette, side, f, shown, x0, y0, size_px) result(svg)
      character(len=*), intent(in) :: title, shown
      integer, intent(in) :: bin(:, :), palette(:, 0:), f
      real(dp), intent(in) :: side
      real(dp), intent(out) :: x0, y0, size_px
      character(len=:), allocatable :: svg, png
      logical :: ok
      size_px = h - mt - mb
      x0 = ml
      y0 = mt
      svg = header(title, xlink=.true.)
      svg = svg//'<rect x="'//fmt(x0)//'" y="'//fmt(y0)//'" width="'//fmt(size_px)//'" height="'//fmt(size_px)// &
         '" fill="white" stroke="black"/>'//nl
      png = png_indexed(bin, palette, ok)
      if (ok) svg = svg//'<image x="'//fmt(x0)//'" y="'//fmt(y0)//'" width="'//fmt(size_px)//'" height="'// &
         fmt(size_px)//'" preserveAspectRatio="none" style="image-rendering:pixelated" '// &
         'xlink:href="data:image/png;base64,'//base64(png)//'"/>'//nl
      if (f > 1) svg = svg//text(x0 + size_px/2, y0 - 8, "shown by "//int_str(f)//" x "//int_str(f)// &
         " blocks ("//shown//" of each); the full map is in the .h5 file", "middle", 10)
      svg = svg//text(x0 + size_px/2, h - mb + 40, "x (nm), column j to the right", "middle", 13)
      svg = svg//'<text x="'//fmt(x0 - 55)//'" y="'//fmt(y0 + size_px/2)//'" font-family="sans-serif" '// &
         'font-size="13" text-anchor="middle" transform="rotate(-90 '//fmt(x0 - 55)//' '//fmt(y0 + size_px/2)// &
         ')">y (nm), row i = 0 at the top</text>'//nl
      svg = svg//text(x0, h - mb + 18, "0", "middle", 11)//text(x0 + size_px, h - mb + 18, sig_str(side, 4), "middle", 11)
      svg = svg//text(x0 - 6, y0 + size_px + 4, "0", "end", 11)//text(x0 - 6, y0 + 4, sig_str(side, 4), "end", 11)
   end function map_frame

   !> Plot coordinates (px) of the data point (xv, yv) in the frame x0..x1, y0..y1
   !> (`frame`, axis units: decades on a log axis).
   pure subroutine to_pixels(frame, xv, yv, pxv, pyv)
      real(dp), intent(in) :: frame(4), xv, yv
      real(dp), intent(out) :: pxv, pyv
      pxv = ml + (xv - frame(1))/(frame(2) - frame(1))*(w - ml - mr)
      pyv = h - mb - (yv - frame(3))/(frame(4) - frame(3))*(h - mt - mb)
   end subroutine to_pixels

   !> The document's start; `xlink` declares the namespace an embedded image needs.
   function header(title, xlink) result(svg)
      character(len=*), intent(in) :: title
      logical, intent(in), optional :: xlink
      character(len=:), allocatable :: svg, namespaces
      namespaces = 'xmlns="http://www.w3.org/2000/svg"'
      if (present(xlink)) then
         if (xlink) namespaces = namespaces//' xmlns:xlink="http://www.w3.org/1999/xlink"'
      end if
      svg = '<?xml version="1.0" encoding="UTF-8"?>'//nl// &
         '<svg '//namespaces//' width="'//fmt(w)//'" height="'//fmt(h)//'" viewBox="0 0 '// &
         fmt(w)//' '//fmt(h)//'">'//nl//'<rect width="100%" height="100%" fill="white"/>'//nl// &
         title_lines(title)
   end function header

   !> The title in the 640-pixel width: one line of at most TITLE_CHARACTERS characters
   !> at 14 px, or, when longer, two lines at 12 px broken at the last space that fits
   !> (the second shortened with an ellipsis): a deck's label is often longer than a
   !> line, and was cut at 80 characters, past the figure's edge at 14 px.
   function title_lines(title) result(svg)
      character(len=*), intent(in) :: title
      character(len=:), allocatable :: svg
      !> Characters of a line: sans-serif takes about 0.55 em a character, so 72 at 14 px
      !> and 88 at 12 px are about 555 and 580 px of the 640.
      integer, parameter :: TITLE_CHARACTERS = 72, LONG_LINE = 88
      integer :: cut
      if (len(title) <= TITLE_CHARACTERS) then
         svg = text(w/2, 28.0_dp, xml_escape(title), "middle", 14)
         return
      end if
      cut = index(title(1:LONG_LINE), " ", back=.true.)
      if (cut < LONG_LINE/2) cut = LONG_LINE
      svg = text(w/2, 20.0_dp, xml_escape(title(1:cut)), "middle", 12)// &
         text(w/2, 36.0_dp, xml_escape(shortened(adjustl(title(cut + 1:)), LONG_LINE)), "middle", 12)
   end function title_lines

   !> Frame, ticks, grid and labels.
   function axes(x0, x1, y0, y1, xt, yt, logx, logy, xlabel, ylabel) result(svg)
      real(dp), intent(in) :: x0, x1, y0, y1, xt(:), yt(:)
      logical, intent(in) :: logx, logy
      character(len=*), intent(in) :: xlabel, ylabel
      character(len=:), allocatable :: svg
      real(dp) :: p
      integer :: k
      svg = '<rect x="'//fmt(ml)//'" y="'//fmt(mt)//'" width="'//fmt(w - ml - mr)//'" height="'//fmt(h - mt - mb)// &
         '" fill="none" stroke="black"/>'//nl
      do k = 1, size(xt)
         p = ml + (xt(k) - x0)/(x1 - x0)*(w - ml - mr)
         svg = svg//'<line x1="'//fmt(p)//'" y1="'//fmt(mt)//'" x2="'//fmt(p)//'" y2="'//fmt(h - mb)// &
            '" stroke="#dddddd"/>'//nl//text(p, h - mb + 18, tick_label(xt(k), logx), "middle", 11)
      end do
      do k = 1, size(yt)
         p = h - mb - (yt(k) - y0)/(y1 - y0)*(h - mt - mb)
         svg = svg//'<line x1="'//fmt(ml)//'" y1="'//fmt(p)//'" x2="'//fmt(w - mr)//'" y2="'//fmt(p)// &
            '" stroke="#dddddd"/>'//nl//text(ml - 6, p + 4, tick_label(yt(k), logy), "end", 11)
      end do
      svg = svg//text((ml + w - mr)/2, h - mb + 45, xml_escape(xlabel), "middle", 13)
      svg = svg//'<text x="22" y="'//fmt((mt + h - mb)/2)//'" font-family="sans-serif" font-size="13" '// &
         'text-anchor="middle" transform="rotate(-90 22 '//fmt((mt + h - mb)/2)//')">'//xml_escape(ylabel)//'</text>'//nl
   end function axes

   function tick_label(v, logscale) result(s)
      real(dp), intent(in) :: v
      logical, intent(in) :: logscale
      character(len=:), allocatable :: s
      if (logscale) then
         s = "1e"//int_str(nint(v))
      else
         s = sig_str(v, 4)
      end if
   end function tick_label

   !> Axis limits and ticks: whole decades on a log axis, "nice" steps on a linear one.
   subroutine axis_range(lo, hi, logscale, a0, a1, ticks)
      real(dp), intent(in) :: lo, hi
      logical, intent(in) :: logscale
      real(dp), intent(out) :: a0, a1
      real(dp), allocatable, intent(out) :: ticks(:)
      integer :: k, d0, d1
      if (logscale) then
         ! At most 40 decades (a degenerate curve must not produce a runaway axis).
         d1 = ceiling(min(hi, 300.0_dp))
         d0 = floor(max(lo, hi - 40, -300.0_dp))
         if (d1 == d0) d1 = d0 + 1
         a0 = d0
         a1 = d1
         allocate(ticks(d1 - d0 + 1))
         do k = d0, d1
            ticks(k - d0 + 1) = k
         end do
      else
         ticks = nice_ticks(lo, hi)
         a0 = min(lo, ticks(1))
         a1 = max(hi, ticks(size(ticks)))
         if (a1 == a0) a1 = a0 + 1
      end if
   end subroutine axis_range

   !> About five round tick values covering [lo, hi] (steps 1, 2 or 5 times a power of 10).
   pure function nice_ticks(lo, hi) result(ticks)
      real(dp), intent(in) :: lo, hi
      real(dp), allocatable :: ticks(:)
      real(dp) :: span, step, mag, f
      integer :: k0, k1, k
      span = hi - lo
      if (.not. span > 0) span = max(abs(hi), 1.0_dp)
      mag = 10.0_dp**floor(log10(span/5))
      f = span/5/mag
      if (f < 1.5_dp) then
         step = mag
      else if (f < 3.5_dp) then
         step = 2*mag
      else if (f < 7.5_dp) then
         step = 5*mag
      else
         step = 10*mag
      end if
      k0 = floor(lo/step)
      k1 = ceiling(hi/step)
      if (k1 == k0) k1 = k0 + 1
      allocate(ticks(k1 - k0 + 1))
      do k = k0, k1
         ticks(k - k0 + 1) = k*step
      end do
   end function nice_ticks

   !> "#rrggbb" of 0-255 RGB.
   function rgb_hex(rgb) result(hex)
      integer, intent(in) :: rgb(3)
      character(len=7) :: hex
      write(hex, '("#", 3z2.2)') rgb
   end function rgb_hex

   !> A colour on a viridis-like scale, t in [0, 1].
   function colour(t) result(hex)
      real(dp), intent(in) :: t
      character(len=7) :: hex
      hex = rgb_hex(colour_rgb(t))
   end function colour

   !> The perceptual scale (viridis through five anchors) at t in [0, 1], as 0-255 RGB.
   pure function colour_rgb(t) result(rgb)
      real(dp), intent(in) :: t
      integer :: rgb(3)
      real(dp), parameter :: anchors(3, 5) = reshape([ &
         68, 1, 84, 59, 82, 139, 33, 145, 140, 94, 201, 98, 253, 231, 37], [3, 5])
      real(dp) :: s, f
      integer :: k
      s = max(0.0_dp, min(1.0_dp, t))*4
      k = min(3, int(s))
      f = s - k
      rgb = nint(anchors(:, k + 1)*(1 - f) + anchors(:, k + 2)*f)
   end function colour_rgb

   function text(x, y, s, anchor, size) result(svg)
      real(dp), intent(in) :: x, y
      character(len=*), intent(in) :: s, anchor
      integer, intent(in) :: size
      character(len=:), allocatable :: svg
      svg = '<text x="'//fmt(x)//'" y="'//fmt(y)//'" font-family="sans-serif" font-size="'//int_str(size)// &
         '" text-anchor="'//anchor//'">'//s//'</text>'//nl
   end function text

   !> At most `n` characters, with an ellipsis when cut.
   function shortened(s, n) result(t)
      character(len=*), intent(in) :: s
      integer, intent(in) :: n
      character(len=:), allocatable :: t
      t = s
      if (len(s) > n) t = s(1:n - 3)//"..."
   end function shortened


   !> A coordinate with two decimals.
   function fmt(v) result(s)
      real(dp), intent(in) :: v
      character(len=:), allocatable :: s
      character(len=32) :: buf
      write(buf, '(f0.2)') v
      s = trim(adjustl(buf))
      if (s(1:1) == ".") s = "0"//s
      if (len(s) > 1) then
         if (s(1:2) == "-.") s = "-0"//s(2:)
      end if
   end function fmt

end module femcod_svg
