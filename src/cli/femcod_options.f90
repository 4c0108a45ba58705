!> The command-line option parser every command uses. A command declares its options in
!> one table (name, kind of value, allowed range or choices, help line, and the mode it
!> applies to); `parse_options` checks the arguments against the table and returns
!> their values, and `option_help` prints the table's help lines. No I/O here: errors
!> come back as a status (STATUS_USAGE) with the message the command prints.
!>
!> The scene options shared by `run`, `mkdeck` and the studies (`--pixel`, `--young`,
!> `--poisson`, `--rigid`, `--rigid-factor`, `--maxcont`, `--remove-plane`,
!> `--height-unit`, `--label`)
!> are declared once (scene_options), so they are validated the same way everywhere.
module femcod_options
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use femcod_kinds, only: dp
   use femcod_problem, only: MIN_PIXEL, MAX_PIXEL
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_strings, only: string_type, int_str, format_real, parse_real, parse_integer, parse_real_list, &
      parse_integer_list, split_list
   implicit none
   private
   public :: option_spec, parsed_options, parse_options, option_help, scene_options, FLAG
   public :: flag_option, real_option, integer_option, text_option, choice_option, real_list_option, &
      integer_list_option
   public :: get_option, option_given, refuse_options, option_value_text

   integer, parameter :: FLAG = 0, INT_VALUE = 1, REAL_VALUE = 2, TEXT_VALUE = 3, CHOICE_VALUE = 4, &
      REAL_LIST = 5, INT_LIST = 6

   !> One option of a command.
   type :: option_spec
      !> "--young"; `alias` a short form ("-o") or "".
      character(len=:), allocatable :: name, alias
      integer :: kind = FLAG
      !> The value's name in the help ("E"), and its help text.
      character(len=:), allocatable :: value_name, help
      !> Allowed range of numbers (integers and reals, and every item of a list):
      !> lower < value (or <= when lower_closed), value < upper (or <=).
      real(dp) :: lower = -huge(1.0_dp), upper = huge(1.0_dp)
      logical :: lower_closed = .true., upper_closed = .true.
      !> Choices, separated by "|" ("upper|lower|none"); a list's required length (0: any).
      character(len=:), allocatable :: choices
      integer :: list_length = 0
      !> The mode the option applies to ("": always; the command names its modes, e.g.
      !> "heights" for the height-file options of `run`).
      character(len=:), allocatable :: mode
   end type option_spec

   !> The arguments of one command line, checked against a table: for each option of the
   !> table whether it was given and its value as text (the last one given); the
   !> positional arguments in order.
   type :: parsed_options
      type(option_spec), allocatable :: table(:)
      logical, allocatable :: given(:)
      type(string_type), allocatable :: text(:)
      type(string_type), allocatable :: positional(:)
   end type parsed_options

   !> The value of an option, converted to the variable's type; the variable keeps its
   !> value (the default) when the option was not given.
   interface get_option
      module procedure get_flag, get_integer, get_real, get_text, get_reals, get_integers
   end interface get_option

contains

   ! ---- declaring ----------------------------------------------------------------

   function flag_option(name, help, alias, mode) result(spec)
      character(len=*), intent(in) :: name, help
      character(len=*), intent(in), optional :: alias, mode
      type(option_spec) :: spec
      spec = base(name, FLAG, "", help, alias, mode)
   end function flag_option

   function text_option(name, value_name, help, alias, mode) result(spec)
      character(len=*), intent(in) :: name, value_name, help
      character(len=*), intent(in), optional :: alias, mode
      type(option_spec) :: spec
      spec = base(name, TEXT_VALUE, value_name, help, alias, mode)
   end function text_option

   !> A real in the range (lower, upper); `closed` says which ends are allowed
   !> ("[]" both, "[)" lower only, "(]", "()").
   function real_option(name, value_name, help, lower, upper, closed, alias, mode) result(spec)
      character(len=*), intent(in) :: name, value_name, help
      real(dp), intent(in), optional :: lower, upper
      character(len=2), intent(in), optional :: closed
      character(len=*), intent(in), optional :: alias, mode
      type(option_spec) :: spec
      spec = base(name, REAL_VALUE, value_name, help, alias, mode)
      call set_range(spec, lower, upper, closed)
   end function real_option

   function integer_option(name, value_name, help, lower, upper, alias, mode) result(spec)
      character(len=*), intent(in) :: name, value_name, help
      integer, intent(in), optional :: lower, upper
      character(len=*), intent(in), optional :: alias, mode
      type(option_spec) :: spec
      spec = base(name, INT_VALUE, value_name, help, alias, mode)
      if (present(lower)) spec%lower = lower
      if (present(upper)) spec%upper = upper
   end function integer_option

   function choice_option(name, choices, help, alias, mode) result(spec)
      character(len=*), intent(in) :: name, choices, help
      character(len=*), intent(in), optional :: alias, mode
      type(option_spec) :: spec
      spec = base(name, CHOICE_VALUE, choices, help, alias, mode)
      spec%choices = choices
   end function choice_option

   !> Comma-separated reals, each in the range; `length` items exactly when given.
   function real_list_option(name, value_name, help, lower, upper, closed, length, mode) result(spec)
      character(len=*), intent(in) :: name, value_name, help
      real(dp), intent(in), optional :: lower, upper
      character(len=2), intent(in), optional :: closed
      integer, intent(in), optional :: length
      character(len=*), intent(in), optional :: mode
      type(option_spec) :: spec
      spec = base(name, REAL_LIST, value_name, help, mode=mode)
      call set_range(spec, lower, upper, closed)
      if (present(length)) spec%list_length = length
   end function real_list_option

   function integer_list_option(name, value_name, help, lower, mode) result(spec)
      character(len=*), intent(in) :: name, value_name, help
      integer, intent(in), optional :: lower
      character(len=*), intent(in), optional :: mode
      type(option_spec) :: spec
      spec = base(name, INT_LIST, value_name, help, mode=mode)
      if (present(lower)) spec%lower = lower
   end function integer_list_option

   !> The scene options of height files and generated decks, the same for every command.
   !> `mode` is the mode they apply to in that command.
   function scene_options(mode) result(specs)
      character(len=*), intent(in) :: mode
      type(option_spec), allocatable :: specs(:)
      specs = [ &
         real_option("--pixel", "D", "pixel size in nm (height files that give theirs need none)", lower=MIN_PIXEL, &
            upper=MAX_PIXEL, closed="[]", mode=mode), &
         real_option("--young", "E", "Young's modulus of the elastic body in GPa (default 200)", lower=0.0_dp, &
            closed="()", mode=mode), &
         real_option("--poisson", "NU", "Poisson's ratio of the elastic body (default 0.25)", lower=-1.0_dp, &
            upper=0.5_dp, closed="()", mode=mode), &
         choice_option("--rigid", "upper|lower|none", "the rigid body (default upper)", mode=mode), &
         real_option("--rigid-factor", "R", "modulus of the rigid body and of the contact elements over the "// &
            "elastic one (default 1e10)", lower=1.0_dp, mode=mode), &
         integer_option("--maxcont", "M", "maximum contacts (default 5 % of the pixels)", lower=1, mode=mode), &
         flag_option("--remove-plane", "subtract each surface's least-squares plane", mode=mode), &
         choice_option("--height-unit", "m|mm|um|nm|A|pm", "unit of the heights in files that do not state theirs "// &
            "(default nm; Gwyddion and NanoScope files do)", mode=mode), &
         text_option("--label", "TEXT", "the problem's label (first line of a deck)", mode=mode)]
   end function scene_options

   function base(name, kind, value_name, help, alias, mode) result(spec)
      character(len=*), intent(in) :: name, value_name, help
      integer, intent(in) :: kind
      character(len=*), intent(in), optional :: alias, mode
      type(option_spec) :: spec
      spec%name = name
      spec%kind = kind
      spec%value_name = value_name
      spec%help = help
      spec%alias = ""
      if (present(alias)) spec%alias = alias
      spec%mode = ""
      if (present(mode)) spec%mode = mode
      spec%choices = ""
   end function base

   pure subroutine set_range(spec, lower, upper, closed)
      type(option_spec), intent(inout) :: spec
      real(dp), intent(in), optional :: lower, upper
      character(len=2), intent(in), optional :: closed
      if (present(lower)) spec%lower = lower
      if (present(upper)) spec%upper = upper
      if (present(closed)) then
         spec%lower_closed = closed(1:1) == "["
         spec%upper_closed = closed(2:2) == "]"
      end if
   end subroutine set_range

   ! ---- parsing ------------------------------------------------------------------

   !> Check `args` against `table`. An argument that does not start with "-" (or is "-")
   !> is positional; an option that takes a value takes the next argument. Errors:
   !> unknown options, a missing value, a value out of its kind or range.
   subroutine parse_options(table, args, parsed, status)
      type(option_spec), intent(in) :: table(:)
      type(string_type), intent(in) :: args(:)
      type(parsed_options), intent(out) :: parsed
      type(status_type), intent(inout) :: status
      integer :: i, k
      parsed%table = table
      allocate(parsed%given(size(table)), parsed%text(size(table)), parsed%positional(0))
      parsed%given = .false.
      do k = 1, size(table)
         parsed%text(k)%s = ""
      end do
      i = 1
      do while (i <= size(args))
         associate(key => args(i)%s)
            if (len(key) < 2 .or. key(1:min(1, len(key))) /= "-") then
               parsed%positional = [parsed%positional, string_type(key)]
               i = i + 1
               cycle
            end if
            k = find(table, key)
            if (k == 0) then
               call set_error(status, STATUS_USAGE, "unknown option "//key)
               return
            end if
            ! An option given twice is refused: keeping the last silently would ignore one
            ! (FEMCOD_ARGS in the cluster scripts makes repeats likely).
            if (parsed%given(k)) then
               call set_error(status, STATUS_USAGE, "option "//key//" is given twice ("//table(k)%name// &
                  trim(merge(" or "//table(k)%alias, repeat(" ", 4 + len(table(k)%alias)), len(table(k)%alias) > 0))// &
                  "); give it once")
               return
            end if
            parsed%given(k) = .true.
            if (table(k)%kind == FLAG) then
               i = i + 1
               cycle
            end if
            if (i == size(args)) then
               call set_error(status, STATUS_USAGE, "option "//key//" needs a value ("//expectation(table(k))//")")
               return
            end if
            parsed%text(k)%s = args(i + 1)%s
            call check_value(table(k), args(i + 1)%s, status)
            if (status%code /= 0) return
            i = i + 2
         end associate
      end do
   end subroutine parse_options

   !> The index of the option named `key` (or its alias), 0 if none.
   pure integer function find(table, key) result(k)
      type(option_spec), intent(in) :: table(:)
      character(len=*), intent(in) :: key
      do k = 1, size(table)
         if (table(k)%name == key .or. (len(table(k)%alias) > 0 .and. table(k)%alias == key)) return
      end do
      k = 0
   end function find

   !> A value checked against the option's kind and range.
   subroutine check_value(spec, value, status)
      type(option_spec), intent(in) :: spec
      character(len=*), intent(in) :: value
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: reals(:)
      integer, allocatable :: ints(:)
      real(dp) :: x
      integer :: m
      logical :: ok
      select case (spec%kind)
      case (TEXT_VALUE)
         ok = len(value) > 0
      case (CHOICE_VALUE)
         ok = is_choice(spec%choices, value)
      case (REAL_VALUE)
         call parse_real(value, x, ok)
         if (ok) ok = in_range(spec, x)
      case (INT_VALUE)
         call parse_integer(value, m, ok)
         if (ok) ok = in_range(spec, real(m, dp))
      case (REAL_LIST)
         call parse_real_list(value, reals, ok)
         if (ok) ok = all([(in_range(spec, reals(m)), m = 1, size(reals))])
         if (ok .and. spec%list_length > 0) ok = size(reals) == spec%list_length
      case (INT_LIST)
         call parse_integer_list(value, ints, ok)
         if (ok) ok = all([(in_range(spec, real(ints(m), dp)), m = 1, size(ints))])
      case default
         ok = .true.
      end select
      if (.not. ok) call set_error(status, STATUS_USAGE, spec%name//" expects "//expectation(spec)//", found '"// &
         value//"'")
   end subroutine check_value

   pure logical function in_range(spec, x)
      type(option_spec), intent(in) :: spec
      real(dp), intent(in) :: x
      in_range = ieee_is_finite(x)
      if (spec%lower_closed) then
         in_range = in_range .and. x >= spec%lower
      else
         in_range = in_range .and. x > spec%lower
      end if
      if (spec%upper_closed) then
         in_range = in_range .and. x <= spec%upper
      else
         in_range = in_range .and. x < spec%upper
      end if
   end function in_range

   !> Whether `value` is one of the "|"-separated choices.
   pure logical function is_choice(choices, value)
      character(len=*), intent(in) :: choices, value
      is_choice = index("|"//choices//"|", "|"//value//"|") > 0 .and. len(value) > 0 .and. index(value, "|") == 0
   end function is_choice

   !> What an option's value must be, in words: "a number > 0", "an integer >= 1",
   !> "one of upper, lower, none", "numbers >= 0, comma-separated".
   function expectation(spec) result(text)
      type(option_spec), intent(in) :: spec
      character(len=:), allocatable :: text
      select case (spec%kind)
      case (TEXT_VALUE)
         text = spec%value_name
      case (CHOICE_VALUE)
         text = "one of "//replace_bars(spec%choices)
      case (REAL_VALUE)
         text = "a number"//range_text(spec)
      case (INT_VALUE)
         text = "an integer"//range_text(spec)
      case (REAL_LIST)
         if (spec%list_length > 0) then
            text = int_str(spec%list_length)//" numbers"//range_text(spec)//", comma-separated"
         else
            text = "numbers"//range_text(spec)//", comma-separated"
         end if
      case (INT_LIST)
         text = "integers"//range_text(spec)//", comma-separated"
      case default
         text = "no value"
      end select
   end function expectation

   function range_text(spec) result(text)
      type(option_spec), intent(in) :: spec
      character(len=:), allocatable :: text
      logical :: has_lower, has_upper
      has_lower = spec%lower > -huge(1.0_dp)
      has_upper = spec%upper < huge(1.0_dp)
      if (has_lower .and. has_upper) then
         text = " in "//merge("[", "(", spec%lower_closed)//format_real(spec%lower)//", "//format_real(spec%upper)// &
            merge("]", ")", spec%upper_closed)
      else if (has_lower) then
         text = " "//merge(">=", "> ", spec%lower_closed)
         text = trim(text)//" "//format_real(spec%lower)
      else if (has_upper) then
         text = " "//merge("<=", "< ", spec%upper_closed)
         text = trim(text)//" "//format_real(spec%upper)
      else
         text = ""
      end if
   end function range_text

   pure function replace_bars(choices) result(text)
      character(len=*), intent(in) :: choices
      character(len=:), allocatable :: text
      integer :: k
      text = ""
      do k = 1, len(choices)
         if (choices(k:k) == "|") then
            text = text//", "
         else
            text = text//choices(k:k)
         end if
      end do
   end function replace_bars

   ! ---- reading the values -------------------------------------------------------

   !> Whether the option `name` was given.
   pure logical function option_given(parsed, name)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      integer :: k
      k = find(parsed%table, name)
      option_given = .false.
      if (k > 0) option_given = parsed%given(k)
   end function option_given

   !> The text given for the option `name` ("" when not given).
   function option_value_text(parsed, name) result(text)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      integer :: k
      k = find(parsed%table, name)
      text = ""
      if (k > 0) text = parsed%text(k)%s
   end function option_value_text

   !> An error for the first option given that applies in none of `modes` ("|"-separated
   !> modes in force, "" for none): "OPTION applies TEXT" with the text `what` gives for
   !> that option's mode (pairs "mode=text|..."), else "OPTION applies to MODES only".
   subroutine refuse_options(parsed, modes, what, status)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: modes, what
      type(status_type), intent(inout) :: status
      type(string_type), allocatable :: pairs(:)
      character(len=:), allocatable :: reason
      integer :: k, m, eq
      if (status%code /= 0) return
      do k = 1, size(parsed%table)
         if (.not. parsed%given(k)) cycle
         associate(mode => parsed%table(k)%mode)
            if (applies(mode, modes)) cycle
            reason = "applies to "//replace_bars(mode)//" only"
            pairs = split_at(what, "|")
            do m = 1, size(pairs)
               eq = index(pairs(m)%s, "=")
               if (eq > 0) then
                  if (pairs(m)%s(1:eq - 1) == mode) reason = "applies "//pairs(m)%s(eq + 1:)
               end if
            end do
            call set_error(status, STATUS_USAGE, parsed%table(k)%name//" "//reason)
            return
         end associate
      end do
   end subroutine refuse_options

   !> Whether an option of `mode` ("", or modes separated by "|") applies when `modes`
   !> are in force.
   pure logical function applies(mode, modes)
      character(len=*), intent(in) :: mode, modes
      integer :: start, k
      applies = len(mode) == 0
      start = 1
      do k = 1, len(mode) + 1
         if (k > len(mode)) then
            applies = applies .or. index("|"//modes//"|", "|"//mode(start:k - 1)//"|") > 0
         else if (mode(k:k) == "|") then
            applies = applies .or. index("|"//modes//"|", "|"//mode(start:k - 1)//"|") > 0
            start = k + 1
         end if
      end do
   end function applies

   function split_at(text, separator) result(parts)
      character(len=*), intent(in) :: text
      character(len=1), intent(in) :: separator
      type(string_type), allocatable :: parts(:)
      integer :: start, k
      allocate(parts(0))
      start = 1
      do k = 1, len(text) + 1
         if (k > len(text)) then
            parts = [parts, string_type(text(start:k - 1))]
         else if (text(k:k) == separator) then
            parts = [parts, string_type(text(start:k - 1))]
            start = k + 1
         end if
      end do
   end function split_at

   subroutine get_flag(parsed, name, value)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      logical, intent(inout) :: value
      if (option_given(parsed, name)) value = .true.
   end subroutine get_flag

   subroutine get_integer(parsed, name, value)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      integer, intent(inout) :: value
      logical :: ok
      if (option_given(parsed, name)) call parse_integer(option_value_text(parsed, name), value, ok)
   end subroutine get_integer

   subroutine get_real(parsed, name, value)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      real(dp), intent(inout) :: value
      logical :: ok
      if (option_given(parsed, name)) call parse_real(option_value_text(parsed, name), value, ok)
   end subroutine get_real

   subroutine get_text(parsed, name, value)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      character(len=:), allocatable, intent(inout) :: value
      if (option_given(parsed, name)) value = option_value_text(parsed, name)
   end subroutine get_text

   subroutine get_reals(parsed, name, values)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      real(dp), allocatable, intent(inout) :: values(:)
      logical :: ok
      if (option_given(parsed, name)) call parse_real_list(option_value_text(parsed, name), values, ok)
   end subroutine get_reals

   subroutine get_integers(parsed, name, values)
      type(parsed_options), intent(in) :: parsed
      character(len=*), intent(in) :: name
      integer, allocatable, intent(inout) :: values(:)
      logical :: ok
      if (option_given(parsed, name)) call parse_integer_list(option_value_text(parsed, name), values, ok)
   end subroutine get_integers

   ! ---- help ---------------------------------------------------------------------

   !> The help of a table's options: "  --name VALUE   help", the help in column 25 and
   !> wrapped at 100 columns (a long name gets its help on the next line); the options of
   !> one mode (`mode` "" for those that always apply).
   function option_help(table, mode) result(lines)
      type(option_spec), intent(in) :: table(:)
      character(len=*), intent(in) :: mode
      type(string_type), allocatable :: lines(:)
      character(len=:), allocatable :: head, rest
      integer, parameter :: column = 24, width = 100
      integer :: k, cut
      allocate(lines(0))
      do k = 1, size(table)
         if (table(k)%mode /= mode) cycle
         head = "  "//table(k)%name
         if (len(table(k)%alias) > 0) head = "  "//table(k)%alias//", "//table(k)%name
         if (table(k)%kind /= FLAG) head = head//" "//table(k)%value_name
         if (len(head) < column - 1) then
            head = head//repeat(" ", column - len(head))
         else
            lines = [lines, string_type(head)]
            head = repeat(" ", column)
         end if
         rest = table(k)%help
         do while (len(head) + len(rest) > width)
            cut = index(rest(1:width - len(head) + 1), " ", back=.true.)
            if (cut <= 1) exit
            lines = [lines, string_type(head//rest(1:cut - 1))]
            rest = rest(cut + 1:)
            head = repeat(" ", column)
         end do
         lines = [lines, string_type(head//rest)]
      end do
   end function option_help
end module femcod_options
