!> SHA-256 (FIPS 180-4) of a byte string, as 64 lower-case hex digits: the provenance of
!> the input files in the run record, and the fingerprint that tells whether existing
!> results belong to the same inputs and options. Words are kept in 64-bit integers and
!> reduced modulo 2^32 after every addition.
module femcod_sha256
   use femcod_kinds, only: i8
   implicit none
   private
   public :: sha256_hex

   integer(i8), parameter :: MASK = int(z'FFFFFFFF', i8)
   integer(i8), parameter :: K(0:63) = [int(z'428a2f98', i8), int(z'71374491', i8), int(z'b5c0fbcf', i8), &
      int(z'e9b5dba5', i8), int(z'3956c25b', i8), int(z'59f111f1', i8), int(z'923f82a4', i8), int(z'ab1c5ed5', i8), &
      int(z'd807aa98', i8), int(z'12835b01', i8), int(z'243185be', i8), int(z'550c7dc3', i8), int(z'72be5d74', i8), &
      int(z'80deb1fe', i8), int(z'9bdc06a7', i8), int(z'c19bf174', i8), int(z'e49b69c1', i8), int(z'efbe4786', i8), &
      int(z'0fc19dc6', i8), int(z'240ca1cc', i8), int(z'2de92c6f', i8), int(z'4a7484aa', i8), int(z'5cb0a9dc', i8), &
      int(z'76f988da', i8), int(z'983e5152', i8), int(z'a831c66d', i8), int(z'b00327c8', i8), int(z'bf597fc7', i8), &
      int(z'c6e00bf3', i8), int(z'd5a79147', i8), int(z'06ca6351', i8), int(z'14292967', i8), int(z'27b70a85', i8), &
      int(z'2e1b2138', i8), int(z'4d2c6dfc', i8), int(z'53380d13', i8), int(z'650a7354', i8), int(z'766a0abb', i8), &
      int(z'81c2c92e', i8), int(z'92722c85', i8), int(z'a2bfe8a1', i8), int(z'a81a664b', i8), int(z'c24b8b70', i8), &
      int(z'c76c51a3', i8), int(z'd192e819', i8), int(z'd6990624', i8), int(z'f40e3585', i8), int(z'106aa070', i8), &
      int(z'19a4c116', i8), int(z'1e376c08', i8), int(z'2748774c', i8), int(z'34b0bcb5', i8), int(z'391c0cb3', i8), &
      int(z'4ed8aa4a', i8), int(z'5b9cca4f', i8), int(z'682e6ff3', i8), int(z'748f82ee', i8), int(z'78a5636f', i8), &
      int(z'84c87814', i8), int(z'8cc70208', i8), int(z'90befffa', i8), int(z'a4506ceb', i8), int(z'bef9a3f7', i8), &
      int(z'c67178f2', i8)]

contains

   !> The digest of `bytes`.
   function sha256_hex(bytes) result(hex)
      character(len=*), intent(in) :: bytes
      character(len=64) :: hex
      integer(i8) :: h(0:7), w(0:63), a, b, c, d, e, f, g, hh, t1, t2, s0, s1, bits
      integer(i8) :: nblocks, blk
      integer :: j, tail
      character(len=128) :: last
      character(len=16), parameter :: digits = "0123456789abcdef"
      h = [int(z'6a09e667', i8), int(z'bb67ae85', i8), int(z'3c6ef372', i8), int(z'a54ff53a', i8), &
         int(z'510e527f', i8), int(z'9b05688c', i8), int(z'1f83d9ab', i8), int(z'5be0cd19', i8)]
      ! The message padded: 0x80, zeros, the length in bits as a 64-bit big-endian number.
      nblocks = len(bytes, i8)/64
      tail = int(len(bytes, i8) - 64*nblocks)
      last = repeat(achar(0), 128)
      if (tail > 0) last(1:tail) = bytes(64*nblocks + 1:)
      last(tail + 1:tail + 1) = achar(128)
      bits = 8*len(bytes, i8)
      if (tail < 56) then
         call put_length(last(57:64))
      else
         call put_length(last(121:128))
      end if
      do blk = 0, nblocks + merge(0, 1, tail < 56)
         if (blk < nblocks) then
            call compress(bytes(64*blk + 1:64*blk + 64))
         else
            call compress(last(64*(blk - nblocks) + 1:64*(blk - nblocks) + 64))
         end if
      end do
      do j = 0, 7
         hex(8*j + 1:8*j + 8) = word_hex(h(j))
      end do
   contains
      subroutine put_length(field)
         character(len=8), intent(out) :: field
         integer :: m
         do m = 1, 8
            field(m:m) = achar(int(iand(ishft(bits, -8*(8 - m)), 255_i8)))
         end do
      end subroutine put_length
      subroutine compress(chunk)
         character(len=64), intent(in) :: chunk
         integer :: m
         do m = 0, 15
            w(m) = ior(ior(ishft(int(iachar(chunk(4*m + 1:4*m + 1)), i8), 24), ishft(int(iachar(chunk(4*m + 2:4*m + 2)), &
               i8), 16)), ior(ishft(int(iachar(chunk(4*m + 3:4*m + 3)), i8), 8), int(iachar(chunk(4*m + 4:4*m + 4)), i8)))
         end do
         do m = 16, 63
            s0 = ieor(ieor(rotr(w(m - 15), 7), rotr(w(m - 15), 18)), ishft(w(m - 15), -3))
            s1 = ieor(ieor(rotr(w(m - 2), 17), rotr(w(m - 2), 19)), ishft(w(m - 2), -10))
            w(m) = iand(w(m - 16) + s0 + w(m - 7) + s1, MASK)
         end do
         a = h(0); b = h(1); c = h(2); d = h(3); e = h(4); f = h(5); g = h(6); hh = h(7)
         do m = 0, 63
            s1 = ieor(ieor(rotr(e, 6), rotr(e, 11)), rotr(e, 25))
            t1 = iand(hh + s1 + ieor(iand(e, f), iand(ieor(e, MASK), g)) + K(m) + w(m), MASK)
            s0 = ieor(ieor(rotr(a, 2), rotr(a, 13)), rotr(a, 22))
            t2 = iand(s0 + ieor(ieor(iand(a, b), iand(a, c)), iand(b, c)), MASK)
            hh = g; g = f; f = e
            e = iand(d + t1, MASK)
            d = c; c = b; b = a
            a = iand(t1 + t2, MASK)
         end do
         h = iand(h + [a, b, c, d, e, f, g, hh], MASK)
      end subroutine compress
      pure integer(i8) function rotr(x, n)
         integer(i8), intent(in) :: x
         integer, intent(in) :: n
         rotr = iand(ior(ishft(x, -n), ishft(x, 32 - n)), MASK)
      end function rotr
      function word_hex(x) result(t)
         integer(i8), intent(in) :: x
         character(len=8) :: t
         integer :: m
         do m = 1, 8
            t(m:m) = digits(int(iand(ishft(x, -4*(8 - m)), 15_i8)) + 1:int(iand(ishft(x, -4*(8 - m)), 15_i8)) + 1)
         end do
      end function word_hex
   end function sha256_hex
end module femcod_sha256
