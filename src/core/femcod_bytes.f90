!> Scanning text eight bytes at a time, for the deck reader (femcod_deck) and the decimals
!> of femcod_decimal: a 64-bit word holds text(i:i+7), byte k of the text in bits 8k..8k+7
!> (little-endian order, checked by `words_little_endian`; the readers go byte by byte
!> otherwise), and each test below answers for all eight bytes at once with the high bit of
!> each byte (bit 8k+7) set where the byte passes. The tests are exact for every byte value:
!> the low seven bits are added to a constant that cannot carry out of the byte, and the
!> byte's own high bit is combined after, so no byte's answer leaks into its neighbour's (the
!> common "has a zero byte" trick flags false bytes above a true one).
!> The tests are private so that the compiler inlines them into the scans (a public
!> procedure may be replaced at load time under -fPIC, so it is called, not inlined:
!> 0.05 s instead of 0.005 to 0.010 s for the control bytes of a 21 MB deck).
module femcod_bytes
   use femcod_kinds, only: i8
   implicit none
   private
   public :: words_little_endian, first_control_byte, scan_tokens, count_tokens, eight_digits

   !> The low seven bits of every byte, and the high bit of every byte.
   integer(i8), parameter :: LOW_BITS = int(z'7F7F7F7F7F7F7F7F', i8)
   integer(i8), parameter :: HIGH_BITS = not(LOW_BITS)
   !> One in every byte.
   integer(i8), parameter :: ONES = int(z'0101010101010101', i8)

contains

   !> High bit of each byte of `word` whose value is below `limit` (1 to 128).
   pure integer(i8) function bytes_below(word, limit) result(mask)
      integer(i8), value :: word
      integer, value :: limit
      integer(i8), parameter :: LOW_HALF = int(z'7F7F7F7F', i8), ONES_HALF = int(z'01010101', i8)
      integer(i8) :: step, low, high
      ! low + (128 - limit) reaches 128 exactly when low >= limit, and stays below 256;
      ! summed in halves of four bytes, so that no sum leaves 63 bits (Fortran's
      ! integers do not wrap), then joined by a shift.
      step = (128 - limit)*ONES_HALF
      low = iand(word, LOW_HALF) + step
      high = iand(shiftr(word, 32), LOW_HALF) + step
      mask = iand(not(ior(ior(low, shiftl(high, 32)), word)), HIGH_BITS)
   end function bytes_below

   !> High bit of each byte of `word` equal to `byte` (0 to 127).
   pure integer(i8) function bytes_equal(word, byte) result(mask)
      integer(i8), value :: word
      integer, value :: byte
      mask = bytes_below(ieor(word, int(byte, i8)*ONES), 1)
   end function bytes_equal

   !> The number of bytes of `mask` (high bits only, as the tests above give them) set.
   pure integer function bytes_set(mask) result(n)
      integer(i8), value :: mask
      integer(i8) :: ones
      ! One in the low bit of each byte set, summed by halving shifts (at most 8).
      ones = shiftr(mask, 7)
      ones = ones + shiftr(ones, 32)
      ones = ones + shiftr(ones, 16)
      ones = ones + shiftr(ones, 8)
      n = int(iand(ones, 255_i8))
   end function bytes_set

   !> Whether this machine stores text(i) in the lowest byte of a word (x86-64 and
   !> AArch64 do).
   pure logical function words_little_endian()
      words_little_endian = transfer("a       ", 0_i8) == int(iachar("a"), i8) + int(z'2020202020202000', i8)
   end function words_little_endian

   !> Whether the eight characters of `chunk` are all decimal digits, and if so their
   !> value (0 to 99999999), formed eight at a time: the digits' values in the bytes, then
   !> pairs, fours and the eight joined by one multiply-and-shift each (every product
   !> stays below 2^63). False on a machine that is not little-endian.
   pure subroutine eight_digits(chunk, value, ok)
      character(len=8), intent(in) :: chunk
      integer(i8), intent(out) :: value
      logical, intent(out) :: ok
      integer(i8), parameter :: ZEROS = int(z'3030303030303030', i8), &
         PAIRS = int(z'00FF00FF00FF00FF', i8), FOURS = int(z'0000FFFF0000FFFF', i8), &
         EIGHT = int(z'00000000FFFFFFFF', i8)
      integer(i8) :: word
      value = 0
      word = transfer(chunk, word)
      ok = words_little_endian() .and. iand(word, HIGH_BITS) == 0
      if (ok) ok = bytes_below(word, 58) == HIGH_BITS .and. bytes_below(word, 48) == 0
      if (.not. ok) return
      ! Byte k holds the k-th digit (the most significant first).
      word = word - ZEROS
      word = iand(word*10 + shiftr(word, 8), PAIRS)
      word = iand(word*100 + shiftr(word, 16), FOURS)
      value = iand(word*10000 + shiftr(word, 32), EIGHT)
   end subroutine eight_digits

   !> text(i:i+7) as a word; past `last` (at most i+7) the bytes are blanks.
   pure integer(i8) function word_at(text, i, last) result(word)
      character(len=*), intent(in) :: text
      integer, intent(in) :: i, last
      character(len=8) :: chunk
      if (last - i >= 7) then
         word = transfer(text(i:i + 7), word)
      else
         chunk = " "
         chunk(1:last - i + 1) = text(i:last)
         word = transfer(chunk, word)
      end if
   end function word_at

   !> The position of the first control byte of `text` (below 32 but TAB, LF, FF and CR,
   !> or DEL), huge(0) if there is none; on all threads. Each block of 4 KiB is first
   !> tested as a whole for any byte below 32 or DEL, by one branch-free pass that the
   !> compiler vectorises; only a block that has one (a line end, most often) is scanned
   !> again word by word for the exact test. The last bytes past whole words are padded
   !> with blanks.
   integer function first_control_byte(text) result(first)
      character(len=*), intent(in) :: text
      integer, parameter :: BLOCK_BYTES = 4096
      integer(i8) :: word, found, suspects
      integer :: b, i, last_word
      first = huge(first)
      ! The start of the last whole word.
      last_word = len(text) - mod(len(text), 8) - 7
      !$omp parallel do private(word, found, suspects, i) reduction(min: first) schedule(static)
      do b = 1, last_word, BLOCK_BYTES
         suspects = 0
         do i = b, min(b + BLOCK_BYTES - 8, last_word), 8
            word = transfer(text(i:i + 7), word)
            suspects = ior(suspects, ior(bytes_below(word, 32), bytes_equal(word, 127)))
         end do
         if (suspects == 0) cycle
         do i = b, min(b + BLOCK_BYTES - 8, last_word), 8
            found = control_bytes(transfer(text(i:i + 7), word))
            if (found /= 0) then
               first = min(first, i + trailz(found)/8)
               exit
            end if
         end do
      end do
      if (first == huge(first) .and. mod(len(text), 8) /= 0) then
         i = last_word + 8
         found = control_bytes(word_at(text, i, len(text)))
         if (found /= 0) first = i + trailz(found)/8
      end if
   end function first_control_byte

   !> High bit of each control byte of `word`: below 32 but TAB, LF, FF and CR, or DEL.
   pure integer(i8) function control_bytes(word) result(found)
      integer(i8), value :: word
      found = iand(bytes_below(word, 32), not(ior(ior(bytes_equal(word, 9), bytes_equal(word, 10)), &
         ior(bytes_equal(word, 12), bytes_equal(word, 13)))))
      found = ior(found, bytes_equal(word, 127))
   end function control_bytes

   !> The number of tokens of text(i0:i1) as scan_tokens counts them (separated by the
   !> bytes below 33 and commas; the byte before i0 taken as a separator), faster: a byte
   !> starts a token where it is no separator and the byte before it is one, so each word
   !> is tested against the word one byte before it, read as a word of its own, and the
   !> starts are summed in the bytes of one word for up to 127 words at a time. No word
   !> depends on the last one, and the compiler vectorises the pass.
   pure integer function count_tokens(text, i0, i1) result(count)
      character(len=*), intent(in) :: text
      integer, intent(in) :: i0, i1
      integer(i8), parameter :: EVEN_BYTES = int(z'00FF00FF00FF00FF', i8)
      integer(i8) :: word, before, sums
      integer :: i, k, words
      logical :: after_separator
      count = 0
      if (i0 > i1) return
      if (.not. separator(text(i0:i0))) count = 1
      i = i0 + 1
      do while (i1 - i >= 7)
         words = min(127, (i1 - i + 1)/8)
         sums = 0
         do k = 0, words - 1
            word = transfer(text(i + 8*k:i + 8*k + 7), word)
            before = transfer(text(i + 8*k - 1:i + 8*k + 6), word)
            sums = sums + shiftr(iand(not(separators(word)), separators(before)), 7)
         end do
         ! The bytes' sums (each at most 127) added in pairs, then across the word.
         sums = iand(sums, EVEN_BYTES) + iand(shiftr(sums, 8), EVEN_BYTES)
         sums = sums + shiftr(sums, 32)
         sums = sums + shiftr(sums, 16)
         count = count + int(iand(sums, 65535_i8))
         i = i + 8*words
      end do
      after_separator = separator(text(i - 1:i - 1))
      do i = i, i1
         if (.not. separator(text(i:i)) .and. after_separator) count = count + 1
         after_separator = separator(text(i:i))
      end do
   end function count_tokens

   !> High bit of each byte of `word` that separates tokens: below 33, or a comma.
   pure integer(i8) function separators(word) result(mask)
      integer(i8), value :: word
      mask = ior(bytes_below(word, 33), bytes_equal(word, 44))
   end function separators

   !> Whether the byte `c` separates tokens.
   pure logical function separator(c)
      character, intent(in) :: c
      separator = iachar(c) < 33 .or. c == ","
   end function separator

   !> The tokens of text(i0:i1), separated by the bytes below 33 and commas (a text
   !> without other control bytes: first_control_byte), and its line ends (LF): counted,
   !> and when `first` is given recorded as tokens k0 + 1, ... (first and last byte; with
   !> `line` their lines, from ln0 on). The byte before i0 is taken as a separator. In each word, `starts`
   !> has the high bit of every byte that begins a token (not a separator, after one) and
   !> `stops` of every separator that ends one; tokens close in the order they open, so
   !> the n-th stop ends the n-th token open. Blanks pad the last word.
   pure subroutine scan_tokens(text, i0, i1, k0, ln0, count, ends, first, last, line)
      character(len=*), intent(in) :: text
      integer, intent(in) :: i0, i1, k0, ln0
      integer, intent(out) :: count, ends
      integer, intent(inout), optional :: first(:), last(:)
      integer, intent(inout), optional :: line(:)
      integer(i8) :: word, sep, other, starts, stops, newlines, after_sep, after_other
      integer :: i, k, kstop, ln, b
      logical :: record
      record = present(first)
      k = k0
      kstop = k0
      ln = ln0
      ! The high bit of byte 0: whether the byte before the word was a separator, or not.
      after_sep = 128
      after_other = 0
      do i = i0, i1, 8
         word = word_at(text, i, i1)
         sep = ior(bytes_below(word, 33), bytes_equal(word, 44))
         other = iand(not(sep), HIGH_BITS)
         starts = iand(other, ior(shiftl(sep, 8), after_sep))
         stops = iand(sep, ior(shiftl(other, 8), after_other))
         after_sep = shiftr(sep, 56)
         after_other = shiftr(other, 56)
         newlines = bytes_equal(word, 10)
         if (record) then
            do while (starts /= 0)
               b = trailz(starts)
               k = k + 1
               first(k) = i + b/8
               if (present(line)) line(k) = ln + bytes_set(iand(newlines, maskr(b, i8)))
               starts = ibclr(starts, b)
            end do
            do while (stops /= 0)
               b = trailz(stops)
               kstop = kstop + 1
               last(kstop) = i + b/8 - 1
               stops = ibclr(stops, b)
            end do
         else
            k = k + bytes_set(starts)
         end if
         ln = ln + bytes_set(newlines)
      end do
      ends = ln - ln0
      ! A token that runs to i1 at the end of a full word has no stop.
      if (record .and. kstop < k) last(k) = i1
      count = k - k0
   end subroutine scan_tokens
end module femcod_bytes
