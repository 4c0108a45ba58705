!> `femcod report`: the JSON reader under it, a run's page, a batch's page, and its
!> refusals. What a browser sees (console, rendered figures, the page's numbers against
!> summary.json read by Python's json, an HTML5 parser's errors) is
!> python/tests/test_report.py.
module test_report
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use femcod_json_reader, only: json_leaf, read_json_leaves, leaf_text, leaf_real, leaf_count, JSON_NUMBER, &
      JSON_STRING, JSON_BOOLEAN, JSON_NULL
   use test_support, only: scratch_path, read_text, file_exists, write_text, contains_text, occurrences
   use testdrive, only: new_unittest, unittest_type, error_type, check
   implicit none
   private
   public :: collect_report

   character(len=1), parameter :: nl = new_line("a")

contains

   subroutine collect_report(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("JSON reader: paths, kinds, escapes and counts of a hand-written document", test_json_leaves), &
         new_unittest("JSON reader: a broken document is refused with its line", test_json_errors), &
         new_unittest("run report: every state's maps, the curves, Hertz, patches, no network", test_run_report), &
         new_unittest("batch report: one row a run, the failed deck's message, each run's page", test_batch_report), &
         new_unittest("study report: every figure the resolution study wrote, its tables", test_study_report), &
         new_unittest("report refusals: missing results, a corrupt summary, an existing -o FILE", test_report_refusals) &
         ]
   end subroutine collect_report

   !> A document written by hand: the expected leaves are read off it.
   subroutine test_json_leaves(error)
      type(error_type), allocatable, intent(out) :: error
      type(json_leaf), allocatable :: leaves(:)
      type(status_type) :: st
      character(len=*), parameter :: doc = '{"a": 1.5e-3, "s": "x\"y\\z\u00e9\n", "t": true,' //nl// &
         ' "o": {"n": null, "arr": [1, {"k": -2}, [3, 4]]}, "e": [], "f": false}'
      call read_json_leaves(doc, "hand.json", leaves, st)
      call check(error, st%code, 0, "read: "//st%message)
      if (allocated(error)) return
      ! a, s, t, o.n, o.arr[0], o.arr[1].k, o.arr[2][0], o.arr[2][1], f: nine leaves.
      call check(error, size(leaves), 9, "nine leaves")
      if (allocated(error)) return
      call check(error, leaf_text(leaves, "a") == "1.5e-3" .and. leaves(1)%kind == JSON_NUMBER, "a number as written")
      if (allocated(error)) return
      call check(error, leaf_text(leaves, "s") == 'x"y\z'//achar(195)//achar(169)//achar(10) .and. &
         leaves(2)%kind == JSON_STRING, "escapes undone, \u00e9 as UTF-8")
      if (allocated(error)) return
      call check(error, leaves(3)%kind == JSON_BOOLEAN .and. leaf_text(leaves, "o.n") == "null" .and. &
         leaves(4)%kind == JSON_NULL, "true and null")
      if (allocated(error)) return
      call check(error, leaf_real(leaves, "o.arr[1].k", 0.0_dp), -2.0_dp, "o.arr[1].k")
      if (allocated(error)) return
      call check(error, leaf_text(leaves, "o.arr[2][1]") == "4" .and. leaf_count(leaves, "o.arr") == 3 .and. &
         leaf_count(leaves, "e") == 0, "nested arrays and their lengths")
      if (allocated(error)) return
      call check(error, leaf_real(leaves, "s", 7.0_dp), 7.0_dp, "a string is no number: the fallback")
   end subroutine test_json_leaves

   subroutine test_json_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(json_leaf), allocatable :: leaves(:)
      type(status_type) :: st
      call read_json_leaves('{"a": 1,'//nl//' "b": 2'//nl//' "c": 3}', "broken.json", leaves, st)
      call check(error, st%code, 3, "missing comma: bad input")
      if (allocated(error)) return
      call check(error, index(st%message, "broken.json:3: expected ',' or '}'") == 1, st%message)
      if (allocated(error)) return
      st = status_type()
      call read_json_leaves('{"a": "open', "cut.json", leaves, st)
      call check(error, st%code == 3 .and. contains_text(st%message, "end of a string"), st%message)
      if (allocated(error)) return
      st = status_type()
      call read_json_leaves('{"a": 1} x', "tail.json", leaves, st)
      call check(error, st%code == 3 .and. contains_text(st%message, "end of the text"), st%message)
      if (allocated(error)) return
      st = status_type()
      call read_json_leaves('{"a": nope}', "word.json", leaves, st)
      call check(error, st%code == 3 .and. size(leaves) == 0, "a bad word: refused, no leaves")
   end subroutine test_json_errors

   !> The sphere deck at two loads, plastic and with a tangential force: two states of
   !> pressure, gap, plastic and stick/slip maps (8), two curves, three patch figures.
   subroutine test_run_report(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, html, summary, load_text
      integer :: code, at
      prefix = scratch_path("report-sphere")
      call run_femcod([string_type("run"), string_type("input/sphere_d2.deck"), string_type("-o"), &
         string_type(prefix), string_type("--solver"), string_type("cg"), string_type("--loads"), &
         string_type("300,3000"), string_type("--plastic"), string_type("--hardness"), string_type("20"), &
         string_type("--tangential"), string_type("100"), string_type("--friction"), string_type("0.3"), &
         string_type("--quiet"), string_type("--force")], code)
      call check(error, code, 0, "the run")
      if (allocated(error)) return
      call run_femcod([string_type("report"), string_type(prefix), string_type("-q")], code)
      call check(error, code, 0, "the report")
      if (allocated(error)) return
      html = read_text(prefix//".report.html")
      call check(error, index(html, "<!DOCTYPE html>") == 1 .and. contains_text(html, "</html>"), "a whole page")
      if (allocated(error)) return
      call check(error, occurrences(html, "<svg"), 2 + 2*4 + 3, "figures: 2 curves, 2 states x 4 maps, 3 of patches")
      if (allocated(error)) return
      call check(error, occurrences(html, "contact pressure at ") == 2 .and. occurrences(html, ">gap at ") == 2 .and. &
         occurrences(html, "plastic displacement at ") == 2 .and. occurrences(html, "stick and slip at ") == 2, &
         "each state's four maps")
      if (allocated(error)) return
      ! The label "rigid sphere R=15 nm" gives the Hertz reference (R from the label).
      call check(error, contains_text(html, "Hertz (R = 15 nm"), "the Hertz curve")
      if (allocated(error)) return
      call check(error, .not. (contains_text(html, "http://") .or. contains_text(html, "https://") .or. &
         contains_text(html, " src=") .or. contains_text(html, "url(")), "no network or external reference")
      if (allocated(error)) return
      ! The second state's load as summary.json writes it (read here from the file, not
      ! typed in): the page carries that exact text under its path.
      summary = read_text(prefix//".summary.json")
      at = index(summary, '"loads": [')
      at = at + index(summary(at:), '{"load_nN": ') + len('{"load_nN": ') - 1
      at = at + index(summary(at:), '{"load_nN": ') + len('{"load_nN": ') - 1
      load_text = summary(at:at + index(summary(at:), ",") - 2)
      call check(error, contains_text(html, 'data-path="loads[1].load_nN" data-value="'//load_text//'"'), &
         "the second state's load with its path and the summary's exact text, "//load_text)
   end subroutine test_run_report

   !> Two decks and a broken one in a batch, then `femcod report DIR`.
   subroutine test_batch_report(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, html
      integer :: code
      dir = scratch_path("report-batch")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call write_text(dir//"/broken.deck", "a deck cut short"//nl//"3 1"//nl)
      call run_femcod([string_type("run"), string_type("input/sphere_d4.deck"), string_type("input/square_punch_n3.deck"), &
         string_type(dir//"/broken.deck"), string_type("--outdir"), string_type(dir), string_type("--quiet"), &
         string_type("--figures"), string_type("none")], code)
      call check(error, code, 3, "the broken deck's exit code")
      if (allocated(error)) return
      call check(error, contains_text(read_text(dir//"/broken.failed.json"), '"exit_code": 3'), "the failure record")
      if (allocated(error)) return
      call run_femcod([string_type("report"), string_type(dir), string_type("-q")], code)
      call check(error, code, 0, "the batch report")
      if (allocated(error)) return
      html = read_text(dir//"/report.html")
      call check(error, occurrences(html, '.report.html">'), 2, "one linked row a run")
      if (allocated(error)) return
      call check(error, file_exists(dir//"/sphere_d4.report.html") .and. file_exists(dir//"/square_punch_n3.report.html"), &
         "each run's own page")
      if (allocated(error)) return
      call check(error, contains_text(html, "expected 3 values (NP PIXEL MAXCONT), found 2 values") .and. &
         contains_text(html, 'id="failed"'), "the failed deck and its message")
      if (allocated(error)) return
      call check(error, occurrences(html, "<svg"), 1, "one figure of every area-load curve")
      if (allocated(error)) return
      ! An event run without requested states: its curves and the last step's map.
      html = read_text(dir//"/sphere_d4.report.html")
      call check(error, occurrences(html, "<svg") == 3 .and. contains_text(html, "contact pressure at the last step"), &
         "a run without states: two curves and the last step's pressure map")
   end subroutine test_batch_report

   !> The resolution study of the small rough deck: its page inlines every SVG file the
   !> study wrote (counted by the shell, so a figure added to the study and not to the
   !> report's list fails here) and shows its five tables.
   subroutine test_study_report(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, html, listing
      integer :: code, figures, ios
      prefix = scratch_path("report-resolution")
      call run_femcod([string_type("resolution"), string_type("input/rough_selfaffine_32.deck"), string_type("-o"), &
         string_type(prefix), string_type("-q"), string_type("--force")], code)
      call check(error, code, 0, "the study")
      if (allocated(error)) return
      call execute_command_line("ls "//prefix//".*.svg | wc -l > "//prefix//".count")
      listing = read_text(prefix//".count")
      read(listing, *, iostat=ios) figures
      call check(error, ios == 0 .and. figures > 0, "the study's figures counted")
      if (allocated(error)) return
      call run_femcod([string_type("report"), string_type(prefix), string_type("-q")], code)
      call check(error, code, 0, "the report")
      if (allocated(error)) return
      html = read_text(prefix//".report.html")
      call check(error, occurrences(html, "<svg"), figures, "every figure of the study")
      if (allocated(error)) return
      call check(error, contains_text(html, "tables.resolution (") .and. contains_text(html, ">tables.powerlaw<"), &
         "its tables")
   end subroutine test_study_report

   subroutine test_report_refusals(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix
      integer :: code
      prefix = scratch_path("report-refused")
      call execute_command_line("rm -f "//prefix//".*")
      call run_femcod([string_type("report"), string_type(prefix), string_type("-q")], code)
      call check(error, code == 3 .and. .not. file_exists(prefix//".report.html"), "no results: exit 3, no page")
      if (allocated(error)) return
      call write_text(prefix//".summary.json", '{"femcod_version": "0.2.0",'//nl//'  "steps": }'//nl)
      call run_femcod([string_type("report"), string_type(prefix), string_type("-q")], code)
      call check(error, code == 3 .and. .not. file_exists(prefix//".report.html"), "a corrupt summary: exit 3, no page")
      if (allocated(error)) return
      call write_text(prefix//".mine.html", "a user's page")
      call run_femcod([string_type("report"), string_type(prefix), string_type("-o"), string_type(prefix//".mine.html"), &
         string_type("-q")], code)
      call check(error, code == 5 .and. read_text(prefix//".mine.html") == "a user's page", &
         "an existing -o FILE without --force: exit 5, kept")
      if (allocated(error)) return
      call run_femcod([string_type("report"), string_type("a"), string_type("b")], code)
      call check(error, code, 2, "two targets: usage")
   end subroutine test_report_refusals
end module test_report
