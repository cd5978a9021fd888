// Method (c)'s fallback when the register is empty (`traverse::UncleHops`): iterative
// backtracking over uncle links. The current node knows the siblings of its ancestors one and two
// levels up (a leaf also three); beyond them, each hop reads the farthest known one's own uncle
// and grand uncle, climbing two levels per read.

// The sibling of the ancestor `levels` levels up; `links[j - 1]` is the sibling of the ancestor
// `j` levels up (a leaf's third link or NONE). `key` is unused here.
fn fallback_find(key: Key, levels: u32, links: vec3<u32>) -> u32 {
    var known = select(3u, 2u, is_none(links.z));
    var have = links;
    var rest = levels;
    while rest > known {
        let via = have[known - 1u];
        if is_none(via) {
            return NONE;
        }
        rest = rest - known;
        rec_link_read();
        // Hops use the first two links, which every node has at a fixed place.
        have = vec3<u32>(hop_links(via), NONE);
        known = 2u;
    }
    rec_backtrack(levels, VIA_ITERATIVE);
    // `rest` is at least 1: a target one level up or less is always in the register.
    return have[max(rest, 1u) - 1u];
}
