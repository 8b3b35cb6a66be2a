; kernels/examples/filter_demo.s -- one stream filter on the simulated machine, the building
; block of Gribble & Ramani 2008 (Sec. 3.1, Fig. 2 and 5), run by `make run`.
;
; 1. Build an ID stream 0..NRAYS-1 in ID-stream memory (sapp, N IDs at a time).
; 2. Give every ray a coordinate x = frac(id * 0.618034) in its ray-buffer record (scatter).
; 3. Filter: gather x by ID, test 0.25 <= x < 0.75 in N-wide SIMD, feed the mask to the
;    partition unit, and partition the stream in place: kept rays move to the front.
; 4. Check the result: walk the kept partition and count rays whose x is out of range.
;
; Result registers:  r10 = rays kept by the partition unit
;                    r11 = rays that passed the test (sum of mask popcounts; must equal r10)
;                    r12 = kept rays whose x fails the test (must be 0)

NRAYS   = 1000          ; stream length (a multiple of N is not required: tails are masked)
FIELD_X = 0             ; byte offset of the x array in a ray buffer (structure of arrays)

        .text
        li      r20, 0              ; base register for ray-buffer field offsets
        rdn     r4                  ; N, the SIMD width of this machine
        viota   v0                  ; lane index
        li      r1, 0               ; next ID to append
        li      r2, 0               ; append pointer into IDM (bytes)
        li      r3, NRAYS
fill:   sub     r5, r3, r1          ; IDs still to append
        mtail   m1, r5              ; tail mask for the last, partial vector
        vbcast  v1, r1
        vadd    v2, v0, v1
        sapp    r2, v2 @m1          ; append the m1 lanes of v2 to the stream
        add     r1, r1, r4
        blt     r1, r3, fill

        li      r6, 0               ; stream begin (bytes into IDM)
        li      r7, NRAYS * 4       ; stream end
        li      r8, 0.618034
        vbcast  v3, r8
        mov     r9, r6
xinit:  sfetch  v4, m1, r9, r7      ; N IDs and their tail mask; r9 advances
        vcvtif  v5, v4 @m1
        vfmul   v5, v5, v3 @m1
        vffloor v6, v5 @m1
        vfsub   v5, v5, v6 @m1      ; x = frac(id * 0.618034)
        rsct    v5, v4, r20, FIELD_X @m1
        blt     r9, r7, xinit

        stage   1                   ; count the filter as traversal work (a box-test filter)
        li      r13, 0.25
        vbcast  v7, r13
        li      r14, 0.75
        vbcast  v8, r14
        li      r11, 0
        mov     r9, r6
filter: sfetch  v4, m1, r9, r7
        rgat    v5, v4, r20, FIELD_X @m1
        vfle    m2, v7, v5 @m1      ; 0.25 <= x
        vflt    m3, v5, v8 @m1      ; x < 0.75
        mand    m2, m2, m3
        pmask   m2                  ; to the partition unit's mask queue
        mpop    r15, m2
        add     r11, r11, r15
        blt     r9, r7, filter
        part    r16, r6, r7         ; in-place partition: kept IDs now in [r6, r16)
        sub     r10, r16, r6
        shri    r10, r10, 2

        stage   0
        li      r12, 0
        mov     r9, r6
check:  bge     r9, r16, done
        sfetch  v4, m1, r9, r16
        rgat    v5, v4, r20, FIELD_X @m1
        vflt    m2, v5, v7 @m1      ; x < 0.25: should not be here
        vfle    m3, v8, v5 @m1      ; x >= 0.75: should not be here
        mor     m2, m2, m3
        mpop    r15, m2
        add     r12, r12, r15
        jmp     check
done:   halt
