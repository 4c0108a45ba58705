!> The pieces of femcod's HTML reports (`femcod report`): one self-contained page (its
!> style and its one small script inline, no network reference), figures inlined as SVG,
!> and tables built from the leaves of a result's JSON so that every number on the page
!> carries the JSON path and text it came from (`data-path`, `data-value`): the browser
!> test compares them with the file.
module femcod_html
   use femcod_kinds, only: dp
   use femcod_strings, only: string_type, xml_escape, sig_str, int_str, text_builder, add_text, built_text
   use femcod_json_reader, only: json_leaf, JSON_NUMBER
   implicit none
   private
   public :: html_page, inline_svg, leaf_cell, leaf_rows_table, members_table, array_table, every_value_table
   public :: is_member, array_names

   character(len=1), parameter :: nl = new_line("a")

   !> The page's style: a readable column, figures two to a row, tables that scroll
   !> sideways rather than overflow.
   character(len=*), parameter :: STYLE = &
      "body{font-family:sans-serif;margin:1.5em auto;max-width:1320px;padding:0 1em;color:#222}"//nl// &
      "h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;margin-top:1.6em}"//nl// &
      "nav a{margin-right:1em}.figures{display:flex;flex-wrap:wrap;gap:12px}"//nl// &
      "figure{margin:0}figure svg{width:640px;max-width:100%;height:auto;border:1px solid #eee}"//nl// &
      ".scroll{overflow-x:auto}table{border-collapse:collapse;font-size:.9em;margin:.5em 0}"//nl// &
      "th,td{border:1px solid #ddd;padding:2px 6px;text-align:left}td.num{text-align:right;"// &
      "font-variant-numeric:tabular-nums}"//nl// &
      "thead th{background:#f3f3f3;cursor:pointer}.failed{color:#b00}p.note{color:#555;font-size:.9em}"

   !> Click a column head of a table of class "sortable" to sort by it (numbers by
   !> value, text by text; again to reverse).
   character(len=*), parameter :: SORT_SCRIPT = &
      "document.querySelectorAll('table.sortable').forEach(function(t){"//nl// &
      " t.querySelectorAll('thead th').forEach(function(th,c){th.addEventListener('click',function(){"//nl// &
      "  var b=t.tBodies[0],r=Array.prototype.slice.call(b.rows),up=th.dataset.dir!=='up';th.dataset.dir=up?'up':'down';"//nl// &
      "  r.sort(function(x,y){var a=x.cells[c].dataset.value,z=y.cells[c].dataset.value,p=parseFloat(a),q=parseFloat(z);"//nl// &
      "   var s=(!isNaN(p)&&!isNaN(q))?p-q:String(a).localeCompare(String(z));return up?s:-s;});"//nl// &
      "  r.forEach(function(x){b.appendChild(x);});});});});"

contains

   !> A whole page: `title`, the body's HTML, and the sorting script when asked.
   function html_page(title, body, sortable) result(page)
      character(len=*), intent(in) :: title, body
      logical, intent(in) :: sortable
      character(len=:), allocatable :: page
      page = "<!DOCTYPE html>"//nl//'<html lang="en">'//nl//"<head>"//nl//'<meta charset="utf-8">'//nl// &
         '<meta name="viewport" content="width=device-width, initial-scale=1">'//nl// &
         "<title>"//xml_escape(title)//"</title>"//nl//"<style>"//nl//STYLE//nl//"</style>"//nl//"</head>"//nl// &
         "<body>"//nl//body
      if (sortable) page = page//"<script>"//nl//SORT_SCRIPT//nl//"</script>"//nl
      page = page//"</body>"//nl//"</html>"//nl
   end function html_page

   !> An SVG document as a figure inside HTML: without its XML declaration and namespace
   !> declarations (HTML gives inline SVG its namespace), `xlink:href` as SVG 2's `href`.
   function inline_svg(svg) result(html)
      character(len=*), intent(in) :: svg
      character(len=:), allocatable :: html
      integer :: k
      html = svg
      if (index(html, "<?xml") == 1) then
         k = index(html, "?>")
         html = adjustl_lines(html(k + 2:))
      end if
      html = replaced(html, ' xmlns="http://www.w3.org/2000/svg"', "")
      html = replaced(html, ' xmlns:xlink="http://www.w3.org/1999/xlink"', "")
      html = replaced(html, "xlink:href=", "href=")
      html = "<figure>"//html//"</figure>"//nl
   end function inline_svg

   pure function adjustl_lines(s) result(t)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: t
      integer :: k
      k = 1
      do while (k <= len(s))
         if (s(k:k) /= nl .and. s(k:k) /= " ") exit
         k = k + 1
      end do
      t = s(k:)
   end function adjustl_lines

   !> `s` with every `from` replaced by `to`.
   function replaced(s, from, to) result(t)
      character(len=*), intent(in) :: s, from, to
      character(len=:), allocatable :: t
      type(text_builder) :: b
      integer :: start, k
      start = 1
      do
         k = index(s(start:), from)
         if (k == 0) exit
         call add_text(b, s(start:start + k - 2)//to)
         start = start + k - 1 + len(from)
      end do
      call add_text(b, s(start:))
      t = built_text(b)
   end function replaced

   !> A table cell for a leaf: its value for a reader (a number to 6 significant
   !> digits), its path and exact text in data attributes.
   function leaf_cell(leaf) result(td)
      type(json_leaf), intent(in) :: leaf
      character(len=:), allocatable :: td
      real(dp) :: x
      integer :: ios
      character(len=:), allocatable :: shown
      shown = xml_escape(leaf%text)
      if (leaf%kind == JSON_NUMBER) then
         read(leaf%text, *, iostat=ios) x
         if (ios == 0) shown = sig_str(x, 6)
         td = '<td class="num" data-path="'//xml_escape(leaf%path)//'" data-value="'//xml_escape(leaf%text)//'">'// &
            shown//"</td>"
      else
         td = '<td data-path="'//xml_escape(leaf%path)//'" data-value="'//xml_escape(leaf%text)//'">'//shown//"</td>"
      end if
   end function leaf_cell

   !> A two-column table: for each path present among the leaves, its label and value.
   function leaf_rows_table(leaves, paths, labels) result(html)
      type(json_leaf), intent(in) :: leaves(:)
      type(string_type), intent(in) :: paths(:), labels(:)
      character(len=:), allocatable :: html
      integer :: k, m
      html = "<table>"//nl
      do k = 1, size(paths)
         do m = 1, size(leaves)
            if (leaves(m)%path /= paths(k)%s) cycle
            html = html//"<tr><th>"//xml_escape(labels(k)%s)//"</th>"//leaf_cell(leaves(m))//"</tr>"//nl
            exit
         end do
      end do
      html = html//"</table>"//nl
   end function leaf_rows_table

   !> True when `path` is a direct member of `parent` ("parent.name", no deeper level).
   pure logical function is_member(path, parent)
      character(len=*), intent(in) :: path, parent
      integer :: m
      is_member = .false.
      m = len(parent)
      if (len(path) <= m + 1) return
      if (path(1:m + 1) /= parent//".") return
      is_member = scan(path(m + 2:), ".[") == 0
   end function is_member

   !> The direct scalar members of the object at `parent`, one row each (name, value).
   function members_table(leaves, parent) result(html)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: parent
      character(len=:), allocatable :: html
      integer :: k
      html = ""
      do k = 1, size(leaves)
         if (.not. is_member(leaves(k)%path, parent)) cycle
         html = html//"<tr><th>"//xml_escape(leaves(k)%path(len(parent) + 2:))//"</th>"//leaf_cell(leaves(k))// &
            "</tr>"//nl
      end do
      if (html /= "") html = "<table>"//nl//html//"</table>"//nl
   end function members_table

   !> The names of the arrays directly below the object `parent` ("" the top), in order.
   function array_names(leaves, parent) result(names)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: parent
      type(string_type), allocatable :: names(:)
      character(len=:), allocatable :: rest, name
      integer :: k, b, m
      allocate(names(0))
      m = len(parent)
      do k = 1, size(leaves)
         if (m > 0) then
            if (len(leaves(k)%path) <= m + 1) cycle
            if (leaves(k)%path(1:m + 1) /= parent//".") cycle
            rest = leaves(k)%path(m + 2:)
         else
            rest = leaves(k)%path
         end if
         b = scan(rest, ".[")
         if (b < 2) cycle
         if (rest(b:b) /= "[") cycle
         name = rest(1:b - 1)
         if (size(names) > 0) then
            if (names(size(names))%s == name) cycle
         end if
         names = [names, string_type(name)]
      end do
   end function array_names

   !> The array of objects at `path` as a table: one row an element, one column each
   !> scalar member of the elements (in the order first met). `sortable` adds the class
   !> the page's script sorts. One pass over the leaves.
   function array_table(leaves, path, sortable) result(html)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: path
      logical, intent(in) :: sortable
      character(len=:), allocatable :: html
      type(string_type), allocatable :: columns(:)
      integer, allocatable :: cell(:, :)
      integer :: k, row, col, close_at, ios, m, nrows
      character(len=:), allocatable :: rest
      type(text_builder) :: b
      allocate(columns(0))
      m = len(path)
      nrows = 0
      ! First pass: rows and columns; second: the cell each leaf fills.
      do k = 1, size(leaves)
         if (.not. element_member(leaves(k)%path, row, rest)) cycle
         nrows = max(nrows, row + 1)
         if (.not. any([(columns(col)%s == rest, col = 1, size(columns))])) columns = [columns, string_type(rest)]
      end do
      if (nrows == 0) then
         html = ""
         return
      end if
      allocate(cell(size(columns), nrows), source=0)
      do k = 1, size(leaves)
         if (.not. element_member(leaves(k)%path, row, rest)) cycle
         do col = 1, size(columns)
            if (columns(col)%s == rest) cell(col, row + 1) = k
         end do
      end do
      if (sortable) then
         call add_text(b, '<div class="scroll"><table class="sortable"><thead><tr><th>#</th>')
      else
         call add_text(b, '<div class="scroll"><table><thead><tr><th>#</th>')
      end if
      do col = 1, size(columns)
         call add_text(b, "<th>"//xml_escape(columns(col)%s)//"</th>")
      end do
      call add_text(b, "</tr></thead>"//nl//"<tbody>"//nl)
      do row = 1, nrows
         call add_text(b, '<tr><td class="num" data-value="'//int_str(row)//'">'//int_str(row)//"</td>")
         do col = 1, size(columns)
            if (cell(col, row) > 0) then
               call add_text(b, leaf_cell(leaves(cell(col, row))))
            else
               call add_text(b, '<td data-value=""></td>')
            end if
         end do
         call add_text(b, "</tr>"//nl)
      end do
      call add_text(b, "</tbody></table></div>"//nl)
      html = built_text(b)
   contains
      !> True when p is path[row].name with name a scalar member.
      logical function element_member(p, row, name)
         character(len=*), intent(in) :: p
         integer, intent(out) :: row
         character(len=:), allocatable, intent(out) :: name
         element_member = .false.
         row = -1
         name = ""
         if (len(p) <= m + 3) return
         if (p(1:m + 1) /= path//"[") return
         close_at = index(p(m + 2:), "]")
         if (close_at < 2) return
         read(p(m + 2:m + close_at), *, iostat=ios) row
         if (ios /= 0) return
         if (len(p) < m + close_at + 3) return
         if (p(m + close_at + 2:m + close_at + 2) /= ".") return
         name = p(m + close_at + 3:)
         element_member = scan(name, ".[") == 0
      end function element_member
   end function array_table

   !> Every leaf, path and value, in document order (inside a closed <details>).
   function every_value_table(leaves, source) result(html)
      type(json_leaf), intent(in) :: leaves(:)
      character(len=*), intent(in) :: source
      character(len=:), allocatable :: html
      type(text_builder) :: b
      integer :: k
      call add_text(b, '<details id="every-value"><summary>Every value of '//xml_escape(source)//" ("// &
         int_str(size(leaves))//")</summary>"//nl//'<div class="scroll"><table>'//nl)
      do k = 1, size(leaves)
         call add_text(b, "<tr><th>"//xml_escape(leaves(k)%path)//"</th>"//leaf_cell(leaves(k))//"</tr>"//nl)
      end do
      call add_text(b, "</table></div></details>"//nl)
      html = built_text(b)
   end function every_value_table
end module femcod_html
