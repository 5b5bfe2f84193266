// 64-bit tallies in pairs of u32 (low word, then the high word that takes the carry): counters
// never wrap silently. The pass declares `stats`.

fn add64(slot: u32, v: u32) {
    if v == 0u {
        return;
    }
    let old = atomicAdd(&stats[2u * slot], v);
    if old + v < old {
        atomicAdd(&stats[2u * slot + 1u], 1u);
    }
}
