package org.pdnav.app.ui

import android.content.Context
import android.os.Build
import android.util.TypedValue
import android.view.View
import android.view.WindowInsets
import android.widget.Button
import android.widget.LinearLayout
import android.widget.TextView

/** Small helpers for the programmatically built screens (no layout inflation, no AndroidX). */
internal object Views {
    /** Density-independent pixels -> pixels. */
    fun dp(ctx: Context, v: Int): Int = (v * ctx.resources.displayMetrics.density + 0.5f).toInt()

    fun button(ctx: Context, id: Int, text: CharSequence, onClick: () -> Unit) = Button(ctx).apply {
        this.id = id
        this.text = text
        // one line: the map screen's four buttons share 360 dp on small phones, where the
        // screen pictures (ScreensRoboTest) showed "NAVIGAT / E"; the text shrinks instead
        maxLines = 1
        if (Build.VERSION.SDK_INT >= 26) setAutoSizeTextTypeUniformWithConfiguration(9, 14, 1, TypedValue.COMPLEX_UNIT_SP)
        setOnClickListener { onClick() }
    }

    fun label(ctx: Context, text: CharSequence) = TextView(ctx).apply {
        this.text = text
        setPadding(0, dp(ctx, 8), 0, dp(ctx, 2))
    }

    fun row(ctx: Context, vararg views: View) = LinearLayout(ctx).apply {
        orientation = LinearLayout.HORIZONTAL
        views.forEach { addView(it, LinearLayout.LayoutParams(0, LinearLayout.LayoutParams.WRAP_CONTENT, 1f)) }
    }

    /**
     * targetSdk 35 draws edge to edge: pad [top] by the status bar and [bottom] by the
     * navigation bar (and display cutouts), so no control sits under a system bar.
     */
    fun applySystemBarInsets(root: View, top: View, bottom: View) {
        val topBase = top.paddingTop
        val bottomBase = bottom.paddingBottom
        root.setOnApplyWindowInsetsListener { _, insets ->
            val (t, b, l, r) = systemBars(insets)
            top.setPadding(top.paddingLeft.coerceAtLeast(l), topBase + t, top.paddingRight.coerceAtLeast(r), top.paddingBottom)
            bottom.setPadding(l, bottom.paddingTop, r, bottomBase + b)
            insets
        }
        root.requestApplyInsets()
    }

    /** (top, bottom, left, right) of the system bars and cutouts. */
    fun systemBars(insets: WindowInsets): IntArray = if (Build.VERSION.SDK_INT >= 30) {
        val i = insets.getInsets(WindowInsets.Type.systemBars() or WindowInsets.Type.displayCutout())
        intArrayOf(i.top, i.bottom, i.left, i.right)
    } else {
        @Suppress("DEPRECATION")
        intArrayOf(insets.systemWindowInsetTop, insets.systemWindowInsetBottom, insets.systemWindowInsetLeft, insets.systemWindowInsetRight)
    }

}
